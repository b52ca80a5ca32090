# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""The depth layer: embree renders against analytic depth, and its view gradients (paper and
surface rules) against finite differences."""
import math

import numpy as np
import pytest
import torch
import trimesh

from active_recognition.sensing import geometry as g
from active_recognition.sensing.depth_layer import CameraConfig, DepthCamera, render_views


def sphere(radius=0.3, centre=(0.0, 0.0, 0.0), subdivisions=6):
    m = trimesh.creation.icosphere(subdivisions=subdivisions, radius=radius)
    m.apply_translation(centre)
    return m


def rays(cam, view):
    """Independent ray set-up: origins and unit directions per pixel, from the geometry module."""
    cfg = cam.config
    x, y = g.pixel_grid(cfg.height, cfg.width, cfg.fov_rad, cfg.focal)
    fwd, up, right = g.camera_axes(*view)
    d = cfg.focal * fwd + x.reshape(-1, 1) * up + y.reshape(-1, 1) * right
    cos = cfg.focal / np.linalg.norm(d, axis=1)
    return g.camera_position(*view, cfg.radius), d / np.linalg.norm(d, axis=1, keepdims=True), cos


def test_sphere_depth_matches_closed_form():
    centre, r = np.array([0.05, -0.1, 0.02]), 0.35
    cam = DepthCamera.from_mesh(sphere(r, centre, 7), CameraConfig(height=64, width=64))
    view = (0.8, 2.1)
    o, w, cos = rays(cam, view)
    oc = centre - o
    b = w @ oc
    disc = b ** 2 - oc @ oc + r * r
    t = b - np.sqrt(np.maximum(disc, 0))
    metric = cam.metric(view)[0].ravel()
    # away from the silhouette (grazing rays), the tessellation error is far below 1e-4
    p = o + t[:, None] * w
    incidence = np.abs(((p - centre) / r * w).sum(1))
    good = (disc > 0) & (incidence > 0.3)
    assert good.sum() > 50
    np.testing.assert_allclose(metric[good], (t * cos)[good], atol=1e-4)
    assert np.all(np.isnan(metric[disc < -1e-3]))  # clear misses are NaN in metric mode
    depth = cam.render(view)[0].ravel()
    assert np.all(depth[disc < -1e-3] == 255.0)
    near, far = cam.config.depth_range
    np.testing.assert_allclose(depth[good], ((t * cos)[good] - near) * 255 / (far - near),
                               atol=1e-4 * 255 / (far - near) + 1e-3)


def test_plane_depth_is_flat_along_the_optical_axis():
    # a square facing the camera at theta = 0, at height z = 0.2: z-depth = R - 0.2 everywhere
    plane = trimesh.Trimesh([[-.5, -.5, .2], [.5, -.5, .2], [.5, .5, .2], [-.5, .5, .2]],
                            [[0, 1, 2], [0, 2, 3]])
    cam = DepthCamera.from_mesh(plane, CameraConfig(height=32, width=32, radius=1.0))
    metric = cam.metric((0.0, 0.0))[0]
    hit = np.isfinite(metric)
    assert 0.1 < hit.mean() < 0.2  # (2 atan(0.5/0.8))^2 of a 120 degree view
    np.testing.assert_allclose(metric[hit], 0.8, atol=1e-4)
    # the paper's d = f/sqrt(x^2+y^2+f^2) D - f, with D the ray length, is that same z minus f
    o, w, cos = rays(cam, (0.0, 0.0))
    D = (o[2] - 0.2) / -w[:, 2]
    np.testing.assert_allclose((cos * D - cam.config.focal)[hit.ravel()],
                               0.8 - cam.config.focal, atol=1e-4)


def test_image_up_is_plus_x_at_theta_zero():
    # a small box at +X shows in the top rows; at +Y (left of a camera whose right is -Y), left
    box = trimesh.creation.box(extents=(0.1, 0.1, 0.1))
    for offset, where in (((0.35, 0, 0), "top"), ((0, 0.35, 0), "left")):
        m = box.copy()
        m.apply_translation(offset)
        depth = DepthCamera.from_mesh(m).render((0.0, 0.0))[0]
        rows, cols = np.nonzero(depth < 255)
        if where == "top":
            assert rows.mean() < 28 and abs(cols.mean() - 31.5) < 2
        else:
            assert cols.mean() < 28 and abs(rows.mean() - 31.5) < 2


def test_batch_equals_single_views_and_threads_agree(rng):
    cam = DepthCamera.from_mesh(trimesh.creation.box(extents=(0.9, 0.4, 0.6)))
    views = rng.uniform([0, -math.pi], [math.pi, math.pi], (6, 2))
    batch = cam.render(views)
    single = np.stack([cam.render(v)[0] for v in views])
    np.testing.assert_array_equal(batch, single)
    out = render_views(torch.tensor(views), [cam] * 6)
    np.testing.assert_array_equal(out.numpy(), batch)


def test_bad_configuration_and_meshes_are_refused():
    with pytest.raises(ValueError, match="radius"):
        CameraConfig(radius=-1)
    with pytest.raises(ValueError, match="fov"):
        CameraConfig(fov=4.0)
    with pytest.raises(ValueError, match="face indices"):
        DepthCamera(np.zeros((3, 3)), [[0, 1, 5]])
    with pytest.raises(ValueError, match="rule"):
        render_views(torch.zeros(1, 2), [DepthCamera.from_mesh(sphere(subdivisions=1))], "magic")


def paper_gradient_reference(cam, view, upstream):
    """The paper's formula, written out from METHOD.md without the module's code."""
    t, p = view
    R = cam.config.radius
    o, w, cos = rays(cam, view)
    hits = cam.trace(view)
    D = hits.distance[0]
    hit = np.isfinite(D)
    P = o + np.where(hit, D, 0)[:, None] * w
    dX = {0: R * np.array([math.cos(t) * math.cos(p), math.cos(t) * math.sin(p), -math.sin(t)]),
          1: R * np.array([-math.sin(t) * math.sin(p), math.sin(t) * math.cos(p), 0.0])}
    near, far = cam.config.depth_range
    out = []
    for k in (0, 1):
        dD = ((o - P) / np.where(hit, D, 1)[:, None]) @ dX[k]          # sum_k dD/dX_k dX_k/dt
        dd = cos * dD * 255 / (far - near)                              # dd/dD, normalised
        out.append(np.mean(np.where(hit, upstream.ravel() * dd, 0.0)))
    return np.array(out)


def test_paper_gradient_matches_independent_formula(rng):
    cam = DepthCamera.from_mesh(sphere(0.3, (0.1, 0.05, -0.08), 4), CameraConfig(32, 32))
    view = np.array([0.9, -0.4])
    upstream = rng.normal(size=(32, 32))
    v = torch.tensor(view[None], requires_grad=True)
    depth = render_views(v, [cam], rule="paper")
    (depth * torch.tensor(upstream[None])).sum().backward()
    np.testing.assert_allclose(v.grad[0].numpy(), paper_gradient_reference(cam, view, upstream),
                               rtol=1e-6)
    # "sum" differs from "mean" by the pixel count
    v2 = torch.tensor(view[None], requires_grad=True)
    (render_views(v2, [cam], "paper", "sum") * torch.tensor(upstream[None])).sum().backward()
    np.testing.assert_allclose(v2.grad.numpy(), v.grad.numpy() * 32 * 32, rtol=1e-9)


def ellipsoid():
    m = trimesh.creation.icosphere(subdivisions=6, radius=1.0)
    m.apply_scale([0.42, 0.3, 0.22])
    m.apply_translation([0.05, -0.04, 0.03])
    return m


@pytest.mark.parametrize("mesh_fn", [lambda: sphere(0.3, (0.12, 0.06, -0.09), 6), ellipsoid])
@pytest.mark.parametrize("view", [(0.7, 0.3), (2.2, -1.9)])
def test_surface_gradient_matches_finite_differences(mesh_fn, view):
    cam = DepthCamera.from_mesh(mesh_fn(), CameraConfig(64, 64))
    view, eps = np.array(view), 2e-4
    steps = [np.array(s) * eps for s in ((1, 0), (-1, 0), (0, 1), (0, -1))]
    # pixels that hit in every render: finite differences of the interior, not the silhouette
    mask = cam.trace(view).hit[0]
    for s in steps:
        mask &= cam.trace(view + s).hit[0]
    weights = np.where(mask, 1.0, 0.0)
    v = torch.tensor(view[None], requires_grad=True)
    (render_views(v, [cam], rule="surface", reduction="sum")
     * torch.tensor(weights.reshape(1, 64, 64))).sum().backward()
    for k in (0, 1):
        fd = (cam.render(view + steps[2 * k]) - cam.render(view + steps[2 * k + 1])).ravel()
        fd = (fd.astype(np.float64) * weights).sum() / (2 * eps)
        assert abs(v.grad[0, k].item() - fd) <= 0.05 * abs(fd), (k, v.grad[0, k].item(), fd)


def test_gradient_flows_to_a_parameter_upstream_of_the_view():
    cam = DepthCamera.from_mesh(sphere(0.3, (0.1, 0.0, 0.0), 4), CameraConfig(32, 32))
    a = torch.nn.Parameter(torch.tensor([0.5, 0.2], dtype=torch.float64))
    views = torch.stack([a, a * 2])  # two views that share the parameter
    loss = render_views(views, [cam, cam], rule="surface").mean()
    loss.backward()
    assert a.grad is not None and torch.all(torch.isfinite(a.grad)) and a.grad.abs().sum() > 0
    # chain rule by hand: d/da = g(view1) + 2 g(view2)
    g = []
    for v in (a.detach(), 2 * a.detach()):
        vv = v[None].clone().requires_grad_(True)
        render_views(vv, [cam], rule="surface").mean().backward()
        g.append(vv.grad[0])
    torch.testing.assert_close(a.grad, (g[0] + 2 * g[1]) / 2)


def test_thousands_of_cameras_share_one_embree_device():
    # one embree device per scene used to crash after a few thousand meshes (a training set)
    box = trimesh.creation.box(extents=(0.5, 0.5, 0.5))
    cams = [DepthCamera.from_mesh(box, CameraConfig(9, 9)) for _ in range(3000)]
    assert (cams[-1].render((0.0, 0.0)) < 255).any()


def test_normalise_depth_maps_metres_misses_and_range_ends():
    from active_recognition.sensing.depth_layer import normalise_depth
    cfg = CameraConfig()
    near, far = cfg.depth_range
    mid = (near + far) / 2
    z = np.array([near, mid, far, np.nan, np.inf, near - 0.1, far + 0.1])
    np.testing.assert_allclose(normalise_depth(z, cfg), [0, 127.5, 255, 255, 255, 0, 255], atol=1e-3)
    assert normalise_depth(z, cfg).dtype == np.float32
    assert np.isnan(z[3])  # the input is left as it was


def test_cameras_of_one_config_share_read_only_ray_tables():
    """Thousands of scenes (ModelNet10's 3,928 training shapes) hold one copy of the pixel rays,
    not one each; a camera with its own intrinsics keeps its own, and the shared ones render the
    same depth as a camera's own would."""
    box = trimesh.creation.box(extents=(0.8, 0.5, 0.3))
    cfg = CameraConfig(24, 24, radius=1.5)
    a, b = DepthCamera(box.vertices, box.faces, cfg), DepthCamera(box.vertices, box.faces, cfg)
    assert a._dirs32_t is b._dirs32_t and a.local_dirs is b.local_dirs and a._cos32 is b._cos32
    with pytest.raises(ValueError, match="read-only"):
        a.cos[0] = 1.0
    other = DepthCamera(box.vertices, box.faces, CameraConfig(24, 24, radius=2.0))
    assert other._dirs32_t is not a._dirs32_t
    k = g.Intrinsics.from_fov(24, 24, cfg.fov_rad)
    own = DepthCamera(box.vertices, box.faces, cfg, intrinsics=k)
    assert own._dirs32_t is not a._dirs32_t
    views = np.array([[0.4, 0.3], [1.2, 2.0]])
    np.testing.assert_allclose(own.render(views), a.render(views), atol=1e-3)
    assert (a.render(views) < 255).sum() > 50
