# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""Pictures for people: depth-image grids (PNG) written atomically."""
from __future__ import annotations

import numpy as np

from active_recognition.atomic_files import atomic_path


def plt():
    """matplotlib.pyplot on the Agg backend (no screen needed)."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as pyplot
    return pyplot


def save_figure(fig, path, **kwargs):
    """Save a matplotlib figure as PNG, atomically."""
    with atomic_path(path) as tmp:
        fig.savefig(tmp, format="png", **kwargs)


def depth_grid(images, path, titles=None, columns=None, row_labels=None):
    """Write a grid of normalised depth images (N, H, W) in [0, 255] as a PNG; None leaves a
    cell blank."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from active_recognition.argument_checks import InputError

    images = list(images)
    n = len(images)
    if all(image is None for image in images):
        raise InputError(f"{path}: no images to draw")
    columns = columns or int(np.ceil(np.sqrt(n)))
    rows = int(np.ceil(n / columns))
    fig, axes = plt.subplots(rows, columns, figsize=(1.6 * columns, 1.7 * rows), squeeze=False)
    for i, ax in enumerate(axes.flat):
        ax.set_axis_off()
        if i < n and images[i] is not None:
            ax.imshow(images[i], cmap="viridis", vmin=0, vmax=255)
            if titles is not None:
                ax.set_title(titles[i], fontsize=7)
    if row_labels is not None:
        for r, label in enumerate(row_labels):
            axes[r, 0].text(-0.1, 0.5, label, transform=axes[r, 0].transAxes, ha="right",
                            va="center", fontsize=8)
    fig.tight_layout()
    save_figure(fig, path, dpi=100)
    plt.close(fig)


DEPTH_LABEL = "z-depth (m), the object 1 m across"


def render_mesh(mesh, out, views=0, theta=1.047, phi=0.524, size=64, radius=1.0, fov=None):
    """Depth images of a mesh file as a PNG grid: `views` evenly spread views, or the one view
    (theta, phi), each upright (image down toward -z, as geometry.upright_optical_rotation
    holds a camera), coloured by z-depth in metres beside one colour bar; the mesh is scaled into
    [-0.5, 0.5]^3, so a metre is its longest edge. -> (number of views, share of pixels that
    hit the mesh)."""
    from active_recognition.sensing import geometry
    from active_recognition.sensing.depth_layer import CameraConfig, DepthCamera
    from active_recognition.sensing.meshes import load_mesh

    config = CameraConfig(height=size, width=size, radius=radius, fov=fov)
    cam = DepthCamera(*load_mesh(mesh), config)
    views = geometry.fibonacci_views(views) if views else np.array([[theta, phi]])
    # the model's camera (optical_rotation) sees a level view upside down; the upright camera is
    # it rolled half a turn about the optical axis, and with square pixels about a centred
    # principal point that turns the image half a turn, pixel centre onto pixel centre
    metres = np.rot90(cam.metric(views), 2, axes=(1, 2))  # (B, H, W), NaN = miss
    metric_grid(metres, out, config.depth_range, [f"({t:.2f}, {p:.2f})" for t, p in views])
    return len(views), float(np.isfinite(metres).mean())


def metric_grid(metres, path, limits, titles=None, label=DEPTH_LABEL):
    """Write depth images (N, H, W) in metres (NaN = no return, left blank) as a PNG grid, row 0
    at the top, with one colour bar from limits[0] (near) to limits[1] (far) labelled `label`."""
    pyplot = plt()
    n = len(metres)
    columns = int(np.ceil(np.sqrt(n)))
    rows = int(np.ceil(n / columns))
    inches = (max(1.6 * columns, 2.4) + 1.2, max(1.7 * rows, 2.6))  # the bar's room on the right
    fig, axes = pyplot.subplots(rows, columns, figsize=inches, squeeze=False, layout="constrained")
    cmap = pyplot.get_cmap("viridis").with_extremes(bad="white")
    shown = None
    for i, ax in enumerate(axes.flat):
        ax.set_axis_off()
        if i < n:
            shown = ax.imshow(np.ma.masked_invalid(metres[i]), cmap=cmap, vmin=limits[0],
                              vmax=limits[1], origin="upper", interpolation="nearest")
            if titles is not None:
                ax.set_title(titles[i], fontsize=7)
    bar = fig.colorbar(shown, ax=axes.ravel().tolist(), shrink=0.9)
    bar.set_label(label, fontsize=7)
    bar.ax.tick_params(labelsize=7)
    save_figure(fig, path, dpi=100)
    pyplot.close(fig)


def readable_views(n):
    """A few readable views: the first n of front, side, top, below, three-quarter."""
    views = [(1.57, -1.57), (1.57, 0.0), (0.35, -1.57), (2.6, -1.2), (1.0, -0.8)]
    return np.array(views[:n])


def contact_sheet(name, root, splits, path, sheet_split="test", objects_per_class=2,
                  views_per_object=3, seed=0):
    """A row per class: objects_per_class test objects (train if the test split is empty), each
    from views_per_object views; cells stay blank where a class has fewer objects. The twins:
    each pair seen from a telling view and from one that is not."""
    from active_recognition.sensing.depth_layer import DepthCamera

    if name == "twins":
        from active_recognition.datasets.twins import pair_sheet
        images, labels, titles = pair_sheet(seed)
        depth_grid(images.reshape(-1, *images.shape[2:]), path, columns=4,
                   row_labels=labels, titles=titles * len(labels))
        return
    if sheet_split != "test":  # a generated benchmark's held-out styles
        from active_recognition.datasets import open_dataset
        ds = open_dataset(name, root, sheet_split, cache_dir=splits["test"].cache_dir)
    else:
        ds = splits["test"] if len(splits["test"]) else splits["train"]
    rng, views = np.random.default_rng(seed), readable_views(views_per_object)
    images = []
    for label in range(len(ds.classes)):
        idx = np.flatnonzero(ds.labels() == label)
        row = [img for i in rng.choice(idx, min(objects_per_class, len(idx)), replace=False)
               for img in DepthCamera(*ds.mesh(i)).render(views)]
        images += row + [None] * (objects_per_class * len(views) - len(row))
    depth_grid(images, path, columns=objects_per_class * len(views), row_labels=ds.classes)
