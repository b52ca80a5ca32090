# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""Training's fast rendering gives the reference renders: posed cameras (augmentation as rays
moved into the mesh's frame) against cameras around the moved vertices, both cores against one,
and the episode's look-ups of imitation's candidate renders against rendering them."""
import numpy as np
import pytest
import torch
import trimesh

from active_recognition.datasets.augment import Augment
from active_recognition.sensing import geometry
from active_recognition.sensing.depth_layer import (
    CameraConfig, DepthCamera, both_cores, render_batch, render_views, trace_all,
)
from active_recognition.sensing.meshes import normalise
from active_recognition.training.devices import keep_freed_memory
from active_recognition.training.losses import KnownViews, float32_views

CONFIG = CameraConfig(48, 48, radius=1.5)


def lopsided():
    """A normalised mesh with no symmetry a mirror or a turn could hide: a box, a cylinder off
    to one side, a cone on top."""
    parts = [trimesh.creation.box(extents=(0.8, 0.5, 0.3)),
             trimesh.creation.cylinder(0.12, 0.6, transform=trimesh.transformations.translation_matrix(
                 (0.3, 0.15, 0.2))),
             trimesh.creation.cone(0.15, 0.4, transform=trimesh.transformations.translation_matrix(
                 (-0.2, -0.1, 0.15)))]
    mesh = trimesh.util.concatenate(parts)
    return normalise(mesh.vertices), np.asarray(mesh.faces)


AUGMENTS = {"mirror": dict(mirror=1.0), "stretch": dict(stretch=0.3),
            "frame and floor": dict(frame_error=0.1, floor_cut=0.2),
            "recipe": dict(frame_error=0.05, floor_cut=0.03, stretch=0.2, mirror=0.5),
            "yaw and all": dict(yaw=True, frame_error=0.05, floor_cut=0.1, stretch=0.2, mirror=1.0)}


@pytest.mark.parametrize("name", AUGMENTS)
def test_draw_is_the_affine_map_transform_applies(name):
    v, _ = lopsided()
    aug = Augment(**AUGMENTS[name])
    for seed in range(5):
        moved, lo = aug.transform(v, np.random.default_rng(seed))
        _, lo2, (a, b) = aug.draw(v, np.random.default_rng(seed))
        np.testing.assert_allclose(v @ a.T + b, moved, atol=1e-12)
        np.testing.assert_array_equal(lo, lo2)


@pytest.mark.parametrize("name", AUGMENTS)
def test_posed_camera_renders_as_a_camera_around_the_moved_mesh(name):
    v, f = lopsided()
    aug = Augment(**AUGMENTS[name])
    base, views = DepthCamera(v, f, CONFIG), geometry.fibonacci_views(12)
    near = 0
    for seed in range(6):
        ref = aug.camera(v, f, CONFIG, np.random.default_rng(seed))
        fast = aug.camera(v, None, CONFIG, np.random.default_rng(seed), base=base)  # same draw
        np.testing.assert_array_equal(ref.crop[0], fast.crop[0])
        hr, hf = ref.trace(views), fast.trace(views)
        dr, df = ref.render_hits(hr), fast.render_hits(hf)
        assert (dr < 255).mean() > 0.05  # the object is in view
        assert np.mean(np.abs(dr - df) < 1e-2) > 0.999  # a ray grazing an edge may go either way
        both = hr.hit & hf.hit
        assert np.mean(np.abs(hr.distance[both] - hf.distance[both]) < 1e-4) > 0.999
        # the normals in the world: parallel (a coplanar twin face may answer), and the surface
        # gradient, which reads them, the same
        nr, nf = hr.world_normals()[both], hf.world_normals()[both]
        cos = np.abs((nr * nf).sum(1)) / np.linalg.norm(nr, axis=1) / np.linalg.norm(nf, axis=1)
        near += np.mean(cos > 1 - 1e-5)
        jr, jf = ref.jacobian(hr, views, "surface"), fast.jacobian(hf, views, "surface")
        assert np.mean(np.abs(jr - jf).max(-1) <= 1e-2 * (1 + np.abs(jr).max(-1))) > 0.995
    assert near / 6 > 0.999


@pytest.mark.parametrize("name", AUGMENTS)
def test_a_render_asks_embree_for_distances_alone_and_gets_the_traces_depth(name):
    """render() traces without the face normals (embree's distance query): bit for bit the depth
    of the full trace, for plain, posed and cropped cameras."""
    v, f = lopsided()
    base, views = DepthCamera(v, f, CONFIG), geometry.fibonacci_views(12)
    for cam in (base, Augment(**AUGMENTS[name]).camera(v, None, CONFIG, np.random.default_rng(3), base=base)):
        light = cam.trace(views, normals=False)
        assert light.normals is None
        np.testing.assert_array_equal(light.distance, cam.trace(views).distance)
        np.testing.assert_array_equal(cam.render(views), cam.render_hits(cam.trace(views)))


def test_posed_camera_moves_nothing_with_the_identity_and_keeps_its_base():
    v, f = lopsided()
    base = DepthCamera(v, f, CONFIG)
    views = geometry.fibonacci_views(8)
    before = base.render(views)
    posed = base.posed(np.eye(3), np.zeros(3))
    np.testing.assert_array_equal(posed.render(views), before)
    moved = base.posed(np.diag([-1.0, 1.0, 1.0]), np.zeros(3))  # the mirror image: image flipped
    assert posed.scene is base.scene and base.pose is None
    np.testing.assert_array_equal(base.render(views), before)
    # the mirror x -> -x seen from (theta, pi - phi) is the image flipped left to right
    mirrored = np.stack([views[:, 0], np.pi - views[:, 1]], -1)
    same = np.abs(moved.render(mirrored) - before[..., ::-1]) < 1e-2
    assert same.mean() > 0.995


def test_both_cores_render_what_one_renders(rng):
    v, f = lopsided()
    aug = Augment(stretch=0.2, mirror=0.5)
    base = DepthCamera(v, f, CONFIG)
    cams = [aug.camera(v, None, CONFIG, rng, base=base) for _ in range(7)] + [base]
    views = rng.uniform([0, -np.pi], [np.pi, np.pi], (8, 2))
    one = [c.trace(x) for c, x in zip(cams, views)]
    two = trace_all(cams, views)
    for a, b in zip(one, two):
        np.testing.assert_array_equal(a.distance, b.distance)
        np.testing.assert_array_equal(a.normals, b.normals)
    sets = [geometry.random_views(rng, 3) for _ in cams]
    np.testing.assert_array_equal(render_batch(cams, sets), np.concatenate([c.render(s) for c, s in zip(cams, sets)]))
    cands = geometry.fibonacci_views(5)
    np.testing.assert_array_equal(render_batch(cams, cands), np.concatenate([c.render(cands) for c in cams]))
    bare = trace_all(cams, views, normals=False)  # the paper rule's renders: distances alone
    assert all(h.normals is None for h in bare)
    np.testing.assert_array_equal(np.concatenate([h.distance for h in bare]),
                                  np.concatenate([h.distance for h in one]))
    # one normalising pass over cameras that share their table, one at a time otherwise
    other = DepthCamera(v, f, CameraConfig(48, 48, radius=2.0))
    for group in (cams, cams[:3] + [other] + cams[4:]):
        np.testing.assert_array_equal(render_views(torch.from_numpy(views), group).numpy(),
                                      np.concatenate([c.render(x) for c, x in zip(group, views)]))
        np.testing.assert_array_equal(render_batch(group, sets),
                                      np.concatenate([c.render(s) for c, s in zip(group, sets)]))


def test_both_cores_keep_the_order_and_raise_what_an_item_raises():
    import threading
    seen = set()

    def square(x):
        seen.add(threading.get_ident())
        if x == 13:
            raise ValueError("thirteen")
        return x * x

    assert both_cores(square, range(12)) == [x * x for x in range(12)]
    assert both_cores(square, [5]) == [25] and both_cores(square, []) == []
    with pytest.raises(ValueError, match="thirteen"):
        both_cores(square, range(40))
    with pytest.raises(ValueError, match="thirteen"):  # on either thread, first item or last
        both_cores(square, range(13, 40))


def test_two_threads_casting_one_camera_each_get_their_own_rays(rng):
    """The one-view cast reads its directions from a per-thread buffer: two threads casting
    different views of one camera at once get what each view gets alone."""
    v, f = lopsided()
    cam = DepthCamera(v, f, CONFIG)
    views = rng.uniform([0.2, -np.pi], [np.pi - 0.2, np.pi], (64, 2))
    alone = [cam.trace(x).distance for x in views]
    for _ in range(3):
        for a, b in zip(alone, both_cores(lambda x: cam.trace(x).distance, views)):
            np.testing.assert_array_equal(a, b)


def test_training_keeps_freed_memory_where_malloc_is_glibcs():
    import platform
    assert keep_freed_memory() is (platform.libc_ver()[0] == "glibc")


def test_known_views_are_the_renders_an_episode_asks_for(rng):
    v, f = lopsided()
    cam = DepthCamera(v, f, CONFIG)
    cands = geometry.fibonacci_views(20)
    known = KnownViews(cam, cands, cam.render(float32_views(cands)))
    # an episode holds its views as float32 tensors and renders them as float64
    views = torch.as_tensor(cands[[3, 17, 0]], dtype=torch.float32).double()
    np.testing.assert_array_equal(render_views(views, [known] * 3).numpy(),
                                  render_views(views, [cam] * 3).numpy())
    elsewhere = torch.tensor([[1.234, -0.5]], dtype=torch.float64)  # not a candidate: cast
    np.testing.assert_array_equal(render_views(elsewhere, [known]).numpy(), cam.render(elsewhere.numpy()))
