# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""The viewing sphere: views and camera poses both ways, pixel rays, initial views and the wrap
at the poles, against analytic values."""
import math

import numpy as np
import pytest

from active_recognition.sensing import geometry as g


def test_camera_at_theta_zero_sits_on_z_with_up_along_x():
    for phi in (0.0, 1.3):
        pos = g.camera_position(0.0, phi, radius=2.0)
        np.testing.assert_allclose(pos, [0, 0, 2.0], atol=1e-12)
    fwd, up, right = g.camera_axes(0.0, 0.0)
    np.testing.assert_allclose(fwd, [0, 0, -1], atol=1e-12)
    np.testing.assert_allclose(up, [1, 0, 0], atol=1e-12)
    np.testing.assert_allclose(np.cross(fwd, up), right, atol=1e-12)


def test_position_matches_the_paper_formula(rng):
    t, p = rng.uniform(0, math.pi, 20), rng.uniform(-math.pi, math.pi, 20)
    expected = np.stack([np.sin(t) * np.cos(p), np.sin(t) * np.sin(p), np.cos(t)], -1) * 1.5
    np.testing.assert_allclose(g.camera_position(t, p, 1.5), expected, atol=1e-12)


def test_rotation_order_is_theta_about_y_then_phi_about_z():
    t, p = 0.6, 1.1
    ry = np.array([[math.cos(t), 0, math.sin(t)], [0, 1, 0], [-math.sin(t), 0, math.cos(t)]])
    rz = np.array([[math.cos(p), -math.sin(p), 0], [math.sin(p), math.cos(p), 0], [0, 0, 1]])
    np.testing.assert_allclose(g.view_rotation(t, p), rz @ ry, atol=1e-12)
    # the other order does not put the camera where the paper's formula does
    assert not np.allclose(ry @ rz @ [0, 0, 1], g.camera_position(t, p))
    np.testing.assert_allclose(g.view_rotation(t, p) @ [0, 0, 1], g.camera_position(t, p))
    # one view (scalar maths) and a batch (array maths) agree, shapes included
    batch = g.view_rotation(np.array([t, 0.2]), np.array([p, -2.0]))
    np.testing.assert_allclose(g.view_rotation(np.array([t]), np.array([p]))[0], batch[0], atol=1e-15)
    assert g.view_rotation(np.array([t]), p).shape == (1, 3, 3) and g.view_rotation(t, p).shape == (3, 3)


def test_optical_frame_looks_at_the_centre_and_quaternion_round_trips(rng):
    for t, p in rng.uniform([0, -math.pi], [math.pi, math.pi], (30, 2)):
        pos, q = g.camera_pose(t, p, radius=1.0)
        m = g.quaternion_to_matrix(q)
        np.testing.assert_allclose(m, g.optical_rotation(t, p), atol=1e-9)
        np.testing.assert_allclose(m[:, 2], -pos / np.linalg.norm(pos), atol=1e-9)
        assert abs(np.linalg.det(m) - 1) < 1e-9 and abs(np.linalg.norm(q) - 1) < 1e-9


@pytest.mark.parametrize("theta,phi", [(0.0, 0.0), (math.pi, 2.0), (-0.3, 0.5), (3.5, -3.0),
                                       (7.0, 9.0), (-7.0, -20.0), (2 * math.pi, 0.0)])
def test_wrap_keeps_views_valid_and_the_camera_in_place(theta, phi):
    t, p = g.wrap_view(theta, phi)
    assert 0 <= t <= math.pi and -math.pi <= p < math.pi
    np.testing.assert_allclose(g.camera_position(t, p), g.camera_position(theta, phi), atol=1e-9)
    assert np.all(np.isfinite(g.optical_rotation(t, p)))


def test_wrap_is_differentiable_in_torch():
    torch = pytest.importorskip("torch")
    theta = torch.tensor([-0.2, 0.5, 3.3], requires_grad=True)
    t, p = g.wrap_view(theta, torch.zeros(3))
    t.sum().backward()
    np.testing.assert_allclose(t.detach().numpy(), [0.2, 0.5, 2 * math.pi - 3.3], atol=1e-6)
    np.testing.assert_allclose(theta.grad.numpy(), [-1, 1, -1])
    np.testing.assert_allclose(p.detach().numpy(), [-math.pi, 0, -math.pi], atol=1e-6)


def test_pixel_grid_principal_point_at_centre_and_fov():
    x, y = g.pixel_grid(5, 7, fov=math.radians(90), focal=2.0)
    assert x[2, 3] == 0 and y[2, 3] == 0
    assert x[0, 0] > 0 and y[0, 0] < 0  # top-left: up and left
    half = 2.0 * math.tan(math.radians(45))  # outer pixel edge at f tan(fov/2)
    np.testing.assert_allclose(y[0, -1] + (y[0, 1] - y[0, 0]) / 2, half)


def test_initial_views_are_evenly_spread():
    v = g.fibonacci_views(50)
    pts = g.camera_position(v[:, 0], v[:, 1])
    d = np.linalg.norm(pts[:, None] - pts[None], axis=-1) + np.eye(50) * 9
    nearest = d.min(1)
    assert v.shape == (50, 2) and nearest.min() > 0.5 * nearest.max()
    np.testing.assert_allclose(pts.mean(0), 0, atol=0.05)


def test_straight_path_is_a_great_circle_with_even_steps():
    for start in [(0.0, 0.3), (1.0, -2.0), (math.pi, 0.0)]:
        path = g.straight_path(*start, steps=8, step_angle=0.4)
        pts = g.camera_position(path[:, 0], path[:, 1])
        np.testing.assert_allclose(pts[0], g.camera_position(*start), atol=1e-9)
        steps = np.arccos(np.clip((pts[1:] * pts[:-1]).sum(1), -1, 1))
        np.testing.assert_allclose(steps, 0.4, atol=1e-9)
        normal = np.cross(pts[0], pts[1])
        np.testing.assert_allclose(pts @ normal, 0, atol=1e-9)  # all on one plane: a great circle


def test_view_rotation_derivatives_match_finite_differences(rng):
    t, p = rng.uniform(0, math.pi, 5), rng.uniform(-math.pi, math.pi, 5)
    d = g.view_rotation_derivatives(t, p)
    h = 1e-6
    dt = (g.view_rotation(t + h, p) - g.view_rotation(t - h, p)) / (2 * h)
    dp = (g.view_rotation(t, p + h) - g.view_rotation(t, p - h)) / (2 * h)
    np.testing.assert_allclose(d[:, 0], dt, atol=1e-8)
    np.testing.assert_allclose(d[:, 1], dp, atol=1e-8)


def test_moved_and_inverse_against_a_homogeneous_transform(rng):
    for _ in range(5):
        t, r = rng.normal(size=3), g.view_rotation(rng.uniform(0, np.pi), rng.uniform(-np.pi, np.pi))
        position, rotation = rng.normal(size=3), g.optical_rotation(*rng.uniform(0.1, 3.0, 2))
        h = np.eye(4)
        h[:3, :3], h[:3, 3] = r, t
        pose = np.eye(4)
        pose[:3, :3], pose[:3, 3] = rotation, position
        moved = h @ pose
        got = g.moved(position, rotation, (t, r))
        np.testing.assert_allclose(got[0], moved[:3, 3], atol=1e-12)
        np.testing.assert_allclose(got[1], moved[:3, :3], atol=1e-12)
        back = np.linalg.inv(h)
        np.testing.assert_allclose(g.inverse((t, r))[0], back[:3, 3], atol=1e-12)
        np.testing.assert_allclose(g.inverse((t, r))[1], back[:3, :3], atol=1e-12)
