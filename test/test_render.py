# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""`active-recognition render` writes each view upright, coloured by z-depth in metres beside a
colour bar: read back from the written PNG through the colour map."""
import math

import matplotlib
import numpy as np
import pytest

from active_recognition.cli import main
from active_recognition.training import visualize

RADIUS = 2.0
FRONT = (math.pi / 2, -math.pi / 2)  # level, from -y: the object's front


@pytest.fixture(scope="module")
def step(tmp_path_factory):
    """A wide box (z -0.5..0.1, front face at y = -0.5) under a narrow one set back (z 0.1..0.5,
    front face at y = -0.2): from the front at radius 2, z-depth 1.5 m below and 1.8 m above."""
    import trimesh

    lower = trimesh.creation.box(bounds=[(-0.5, -0.5, -0.5), (0.5, 0.5, 0.1)])
    upper = trimesh.creation.box(bounds=[(-0.2, -0.2, 0.1), (0.2, 0.2, 0.5)])
    path = tmp_path_factory.mktemp("step") / "step.stl"
    trimesh.util.concatenate([lower, upper]).export(path)
    return path


def render(argv, monkeypatch):
    """Run the render subcommand; -> (the PNG it wrote, RGB (H, W, 3), the figure it saved)."""
    figures, save = [], visualize.save_figure

    def keep(fig, path, **kwargs):
        save(fig, path, **kwargs)
        figures.append(fig)
    monkeypatch.setattr(visualize, "save_figure", keep)
    assert main(["render", *map(str, argv)]) == 0
    out = argv[argv.index("--out") + 1]
    assert len(figures) == 1
    return matplotlib.image.imread(out)[..., :3], figures[0]


def pixels(png, fig, artist):
    """The PNG's pixels under a matplotlib artist (its window extent, at the saved size)."""
    box, scale = artist.get_window_extent(), png.shape[0] / fig.bbox.height
    r0, r1 = round((fig.bbox.height - box.y1) * scale), round((fig.bbox.height - box.y0) * scale)
    c0, c1 = round(box.x0 * scale), round(box.x1 * scale)
    return png[r0:r1, c0:c1]


def metres(rgb, limits):
    """Colours back to metres through viridis (NaN where no viridis colour is near: a miss)."""
    table = matplotlib.colormaps["viridis"](np.linspace(0, 1, 256))[:, :3]
    dist = np.linalg.norm(rgb[..., None, :] - table, axis=-1)
    value = limits[0] + dist.argmin(-1) / 255 * (limits[1] - limits[0])
    return np.where(dist.min(-1) < 0.02, value, np.nan)


def test_render_writes_the_view_upright_coloured_in_metres(step, tmp_path, monkeypatch):
    out = tmp_path / "front.png"
    png, fig = render(["--mesh", step, "--theta", FRONT[0], "--phi", FRONT[1], "--radius", RADIUS,
                       "--out", out], monkeypatch)
    (shown,) = [image for ax in fig.axes for image in ax.images]
    bar = shown.colorbar
    assert bar is not None and bar.ax in fig.axes
    assert "(m)" in bar.ax.get_ylabel()
    # the bar spans the model's depth range, the cube's bounding sphere seen from the radius
    limits = (RADIUS - math.sqrt(3) / 2, RADIUS + math.sqrt(3) / 2)
    assert (bar.vmin, bar.vmax) == pytest.approx(limits)
    depth = metres(pixels(png, fig, shown), limits)
    h = depth.shape[0]
    assert 100 <= h <= 400 and abs(depth.shape[1] - h) <= 2  # the square image, scaled up
    near, far = np.abs(depth - 1.5) < 0.02, np.abs(depth - 1.8) < 0.02
    assert near.sum() > 0.15 * depth.size and far.sum() > 0.03 * depth.size
    assert np.isnan(depth[~(near | far)]).mean() > 0.98  # nothing else but the blank background
    rows = np.arange(h)[:, None] * np.ones(depth.shape)
    # the narrow box on top lies in the upper half of the rows; z = 0.1 is 0.1 / 2 of the
    # half-width of the view above the centre, so nearly all of the wide box in the lower half
    assert rows[far].max() < h / 2
    assert (rows[near] > h / 2).mean() > 0.8
    # and the colour bar itself, as written: near (dark) at its bottom, far at its top
    strip = metres(pixels(png, fig, bar.ax), limits)
    column = strip[:, strip.shape[1] // 2]
    assert np.nanargmin(column) > np.nanargmax(column)
    assert np.nanmin(column) == pytest.approx(limits[0], abs=0.02)
    assert np.nanmax(column) == pytest.approx(limits[1], abs=0.02)


def test_every_level_view_is_upright(step, tmp_path, monkeypatch):
    """Level views from four sides: in each the narrow box is above the wide one (the top quarter
    of the silhouette's rows is the narrower at its widest), whatever the azimuth."""
    out = tmp_path / "side.png"
    for phi in (-math.pi / 2, 0.0, 0.8, 3.0):
        png, fig = render(["--mesh", step, "--theta", math.pi / 2, "--phi", phi, "--radius",
                           RADIUS, "--out", out], monkeypatch)
        (shown,) = [image for ax in fig.axes for image in ax.images]
        depth = metres(pixels(png, fig, shown), (shown.norm.vmin, shown.norm.vmax))
        width = np.isfinite(depth).sum(1)
        seen = np.flatnonzero(width > 0)
        top, bottom = seen[:len(seen) // 4], seen[-(len(seen) // 4):]
        assert width[top].max() < 0.6 * width[bottom].max(), phi  # narrow above, wide below
