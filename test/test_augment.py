# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""Augmentation: each transform of a training object (mirror, stretch, yaw, frame error, floor
cut, dropout) against its definition."""
import math

import numpy as np
import pytest
import torch
import trimesh
from test_training import TINY, cache, weights  # noqa: F401  (the cache fixture)

from active_recognition.datasets.augment import Augment, MISS
from active_recognition.sensing.depth_layer import CameraConfig, DepthCamera
from active_recognition.training.train import TrainConfig, train


def long_box():
    m = trimesh.creation.box(extents=(1.0, 0.2, 0.2))
    return np.asarray(m.vertices), np.asarray(m.faces)


def test_yaw_turns_the_object_and_refits_its_box():
    v, _ = long_box()
    rng = np.random.default_rng(5)
    a = np.random.default_rng(5).uniform(-np.pi, np.pi)  # the angle transform will draw
    t, lo = Augment(yaw=True).transform(v, rng)
    c, s = abs(math.cos(a)), abs(math.sin(a))
    ext = np.array([c + 0.2 * s, s + 0.2 * c, 0.2])  # the turned box's bounds, before refitting
    np.testing.assert_allclose(np.ptp(t, 0), ext / ext.max(), atol=1e-9)
    np.testing.assert_allclose(t.max(0) + t.min(0), 0, atol=1e-9)
    np.testing.assert_allclose(lo, -0.6)


def test_yaw_range_keeps_the_turn_within_its_bound():
    """Two corners of the long box one edge apart along x: after the turn (and the refit, which
    only centres and scales) the line between them points at the yaw drawn. Over 200 draws at
    45 degrees every one lies within +-45, and they reach near both bounds."""
    v, _ = long_box()
    i = int(np.argmax(v @ [1, 1e-3, 1e-6]))                    # (0.5, 0.1, 0.1)
    j = int(np.argmin(np.abs(v - v[i] + [1, 0, 0]).sum(1)))  # (-0.5, 0.1, 0.1)
    rng, angles = np.random.default_rng(0), []
    for _ in range(200):
        t, _ = Augment(yaw=True, yaw_range=45).transform(v, rng)
        d = t[i] - t[j]
        angles.append(math.degrees(math.atan2(d[1], d[0])))
    assert np.abs(angles).max() <= 45 and min(angles) < -40 and max(angles) > 40
    with pytest.raises(ValueError, match="yaw_range"):
        Augment(yaw=True, yaw_range=0)
    with pytest.raises(ValueError, match="yaw_range"):
        TrainConfig(yaw=True, yaw_range=270)


def test_a_mirrored_object_shows_the_mirror_image_of_each_view():
    """mirror 1: x -> -x. Seen from the view mirrored with it (phi -> pi - phi), the mirrored
    object's depth image is the original's flipped left to right; mirror 0.5 mirrors about
    half the objects."""
    m = trimesh.creation.box(extents=(0.9, 0.5, 0.3))
    m.apply_translation((0.2, 0.1, 0.05))  # not symmetric about x = 0
    m = trimesh.util.concatenate([m, trimesh.creation.box(extents=(0.1, 0.1, 0.8))])
    v, f = np.asarray(m.vertices), np.asarray(m.faces)
    t, _ = Augment(mirror=1.0).transform(v, np.random.default_rng(0))
    np.testing.assert_allclose(t, v * [-1, 1, 1])
    config = CameraConfig(64, 64)
    views = np.array([[1.1, 0.4], [0.7, -2.0], [2.0, 1.0]])
    mirrored = views.copy()
    mirrored[:, 1] = np.pi - views[:, 1]
    ours = DepthCamera(t, f, config).render(mirrored)
    theirs = DepthCamera(v, f, config).render(views)[:, :, ::-1]
    assert (np.abs(ours - theirs) > 1.0).mean() < 0.01  # but for a pixel where an edge grazes
    assert (np.abs(ours - theirs) > 1.0).sum() < (np.abs(theirs - theirs[:, :, ::-1]) > 1.0).sum()
    rng = np.random.default_rng(1)
    flips = [Augment(mirror=0.5).transform(v, rng)[0][0, 0] == -v[0, 0] for _ in range(200)]
    assert 80 < sum(flips) < 120
    with pytest.raises(ValueError, match="mirror"):
        Augment(mirror=1.5)


def test_stretch_scales_each_axis_within_its_bounds_and_refits_the_box():
    """stretch 0.2: each axis times its own factor in [1/1.2, 1.2], then the box re-fitted
    (centred, longest side 1), so an extent ratio moves by at most 1.2**2 either way; over many
    objects the factors spread across that range and their logs average about 0."""
    v, _ = long_box()
    v = v * [1, 2.5, 4] + [0.3, -0.1, 0.2]  # extents 1 x 0.5 x 0.8, off centre
    base = np.ptp(v, 0)
    logs = []
    for seed in range(300):
        t, _ = Augment(stretch=0.2).transform(v, np.random.default_rng(seed))
        ext = np.ptp(t, 0)
        assert ext.max() == pytest.approx(1.0)
        np.testing.assert_allclose((t.max(0) + t.min(0)) / 2, 0, atol=1e-12)
        f = ext / base  # each axis's factor, up to the common re-fit scale
        assert f.max() / f.min() <= 1.2 ** 2 + 1e-9
        logs.append(np.log(f / f.mean()))
    spread = np.ptp(np.log([f.max() / f.min() for f in np.exp(logs)]))
    assert spread > 0.5 * np.log(1.44)  # the factors really vary
    assert abs(np.mean([x[0] - x[1] for x in logs])) < 0.02  # no axis favoured
    same, _ = Augment().transform(v, np.random.default_rng(0))
    np.testing.assert_array_equal(same, v)
    with pytest.raises(ValueError, match="stretch"):
        Augment(stretch=0.5)
    with pytest.raises(Exception, match="stretch"):
        TrainConfig(stretch=-0.1)


def test_frame_error_moves_and_scales_within_its_bounds():
    v, _ = long_box()
    for seed in range(20):
        t, _ = Augment(frame_error=0.15).transform(v, np.random.default_rng(seed))
        scale = np.ptp(t, 0)[0]  # the true size seen in a box believed 1 +- 15 %
        assert 1 / 1.15 - 1e-9 <= scale <= 1 / 0.85 + 1e-9
        centre = (t.max(0) + t.min(0)) / 2 * scale ** -1  # back in true units
        assert np.linalg.norm(centre) <= 0.15 + 1e-9


def test_the_crop_keeps_exactly_the_hits_inside_the_box():
    v, f = long_box()
    v = v * [1.4, 1, 1] + [0.2, 0, 0]  # sticks out of the +x side
    cfg = CameraConfig(48, 48)
    plain, cropped = DepthCamera(v, f, cfg), DepthCamera(v, f, cfg)
    cropped.crop = (np.full(3, -0.6, np.float32), np.full(3, 0.6, np.float32))
    views = np.array([[1.2, 0.4], [1.57, -1.57], [0.3, 2.0]])
    h = plain.trace(views)
    dirs = np.einsum("bij,nj->bni", h.rotations, plain.local_dirs)
    with np.errstate(invalid="ignore"):
        pts = h.origins[:, None] + dirs * h.distance[..., None]
    inside = h.hit & np.all(np.abs(pts) <= 0.6, axis=-1)
    assert (h.hit & ~inside).sum() > 20  # the test sees a real cut
    np.testing.assert_array_equal(cropped.trace(views).hit, inside)


def test_the_floor_cut_raises_the_bottom_of_the_crop_only():
    v, _ = long_box()
    lo = [Augment(floor_cut=0.1).transform(v, np.random.default_rng(s))[1] for s in range(30)]
    z = np.array([x[2] for x in lo])
    assert np.all(z >= -0.1 - 1e-9) and np.all(z <= -0.1 + 0.1 * 0.2 + 1e-9) and np.ptp(z) > 0
    np.testing.assert_allclose(np.array(lo)[:, :2], -0.6)


@pytest.mark.parametrize("source", ["torch", "numpy"])
def test_dropout_only_turns_pixels_into_misses_at_the_rate_asked(source):
    """Drawn from torch's generator or from numpy's (imitation's candidates): the same rates."""
    torch.manual_seed(0)
    rng = np.random.default_rng(0) if source == "numpy" else None
    depth = torch.full((400, 32, 32), MISS)
    depth[:, 4:28, 4:28] = 100.0  # a flat face: edges only on its rim
    out = Augment(dropout=0.3).images(depth, rng=rng)
    changed = out != depth
    assert torch.all(out[changed] == MISS) and torch.all(out[depth == MISS] == MISS)
    interior = changed[:, 6:26, 6:26].float().mean().item()
    assert abs(interior - 0.15) < 0.01  # a rate drawn uniformly in [0, 0.3] per image
    rim = changed[:, 4, 6:26].float().mean().item()  # edge pixels: dropped twice as often
    assert rim > interior * 1.6
    assert torch.equal(Augment().images(depth), depth)
    if rng is not None:  # numpy's draws are the seed's alone, whatever torch's generator did
        torch.manual_seed(1)
        assert torch.equal(Augment(dropout=0.3).images(depth, rng=np.random.default_rng(0)), out)


def test_chances_drawn_from_numpy_hold_their_probability():
    from active_recognition.datasets.augment import below
    chance = torch.tensor([0.0, 0.02, 0.5, 0.97])[:, None]
    hits = below((4, 200_000), chance, rng=np.random.default_rng(3)).float().mean(1)
    np.testing.assert_allclose(hits.numpy(), chance[:, 0].numpy(), atol=0.004)
    assert hits[0] == 0


def test_steep_dropout_drops_what_a_drivers_flying_pixel_filter_drops():
    """Against simulated_camera.edge_dropout on the same image in metres: the augmentation's
    angle is drawn in 70-85 degrees, so it drops at least what the filter drops at 85 and at
    most what it drops at 70; jumps to the background do not count."""
    from active_recognition.simulation.depth_sensor import edge_dropout
    config = CameraConfig(64, 64, radius=1.5)
    m = trimesh.creation.box(extents=(0.8, 0.5, 0.3))
    m.vertices[:, 2] += 0.1 * m.vertices[:, 0]  # a tilt: a steep top as well as a jump
    cam = DepthCamera(np.asarray(m.vertices), np.asarray(m.faces), config)
    views = np.array([[1.3, 0.4], [0.6, 2.0], [1.55, -1.0], [2.2, 0.9]])
    depth = torch.from_numpy(cam.render(views)).float()
    near, far = config.depth_range
    metres = np.where(depth.numpy() < MISS, near + depth.numpy() * (far - near) / 255.0, np.nan)
    focal = config.intrinsics().fx
    torch.manual_seed(0)
    out = Augment(steep=1.0, view_camera=config).images(depth)
    dropped = ((out == MISS) & (depth < MISS)).numpy()
    for i in range(len(views)):
        most = np.isnan(edge_dropout(metres[i], 70.0, focal)) & ~np.isnan(metres[i])
        least = np.isnan(edge_dropout(metres[i], 85.0, focal)) & ~np.isnan(metres[i])
        assert np.all(dropped[i][least]) and not np.any(dropped[i] & ~most)
    assert dropped.any() and torch.all(out[out != depth] == MISS)
    assert torch.equal(Augment(steep=0.0, view_camera=config).images(depth), depth)
    kept = Augment(steep=0.5, view_camera=config).images(depth.repeat(50, 1, 1))  # a chance per image
    lost = ((kept == MISS) & (depth.repeat(50, 1, 1) < MISS)).flatten(1).any(1).float()
    assert 0.3 < lost.mean() / torch.as_tensor(dropped).flatten(1).any(1).float().mean() < 0.7


def test_steep_dropout_looks_only_at_the_chosen_images_and_gives_what_all_of_them_would():
    """The chosen images alone are filtered: the same pixels as filtering every image and keeping
    the chosen ones, from the same draws (torch's generator and numpy's)."""
    from active_recognition.datasets.augment import uniform
    config = CameraConfig(64, 64, radius=1.5)
    m = trimesh.creation.box(extents=(0.8, 0.5, 0.3))
    m.vertices[:, 2] += 0.1 * m.vertices[:, 0]
    cam = DepthCamera(np.asarray(m.vertices), np.asarray(m.faces), config)
    views = np.random.default_rng(3).uniform([0.3, -3.0], [2.8, 3.0], (40, 2))
    depth = torch.from_numpy(cam.render(views)).float()
    aug = Augment(steep=0.4, view_camera=config)
    for draws in (lambda: {"generator": torch.Generator().manual_seed(5)},
                  lambda: {"rng": np.random.default_rng(5)}):
        out = aug.steep_removed(depth, **draws())
        again = draws()
        chosen = uniform((len(depth), 1, 1), **again) < aug.steep
        angle = torch.deg2rad(70 + 15 * uniform((len(depth), 1, 1), **again))
        every = torch.where(chosen, aug.steep_pixels(depth, angle), depth)
        assert torch.equal(out, every)
        assert 0 < chosen.sum() < len(depth) and not torch.equal(out, depth)
    none = Augment(steep=1e-9, view_camera=config).steep_removed(depth, generator=torch.Generator().manual_seed(0))
    assert torch.equal(none, depth)


def test_bad_augmentation_is_refused_by_name():
    with pytest.raises(ValueError, match="frame_error"):
        TrainConfig(frame_error=0.7)
    with pytest.raises(ValueError, match="dropout"):
        Augment(dropout=-0.1)
    with pytest.raises(ValueError, match="steep"):
        TrainConfig(steep_dropout=1.5)
    with pytest.raises(ValueError, match="camera"):
        Augment(steep=0.5)


@pytest.mark.slow
def test_training_with_every_augmentation_runs_and_learns_finite_weights(tmp_path):
    cfg = TrainConfig(**{**TINY, "out": str(tmp_path / "run"), "yaw": True, "frame_error": 0.15,
                         "floor_cut": 0.03, "dropout": 0.3,
                         "steep_dropout": 0.5})
    train(cfg, progress=False)
    w = weights(tmp_path / "run" / "final.pt")
    assert all(torch.isfinite(t).all() for t in w.values())
    fresh = weights(tmp_path / "run" / "pretrained.pt")
    assert any(not torch.equal(w[k], fresh[k]) for k in w)  # the joint stage trained
