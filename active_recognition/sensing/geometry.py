# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""The viewing sphere: views (theta, phi) <-> camera frames, pixel rays, initial views, paths.

Conventions (METHOD.md, the paper's equations):
- camera position X = R (sin t cos p, sin t sin p, cos t);
- the camera frame of view (t, p) is Rz(p) @ Ry(t) applied to the frame at t = 0, where the
  camera sits at (0, 0, R), looks down -Z and has its up direction along +X;
- image rows run against "up", image columns along "right" = forward x up (-Y at t = 0), so the
  ROS optical frame (x right, y down, z forward; REP 103) is (right, -up, forward).
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from functools import lru_cache

import numpy as np

from active_recognition.argument_checks import InputError

CUBE_RADIUS = math.sqrt(3.0) / 2.0  # bounding-sphere radius of [-0.5, 0.5]^3


def view_rotation(theta, phi):
    """Rz(phi) @ Ry(theta), shape (..., 3, 3): maps the t = 0 camera frame to view (t, p)."""
    t, p = np.asarray(theta, dtype=np.float64), np.asarray(phi, dtype=np.float64)
    if t.size == 1 and p.size == 1:  # one view (the renderer's common case): scalar maths
        ct, st, cp, sp = math.cos(t.item()), math.sin(t.item()), math.cos(p.item()), math.sin(p.item())
        m = np.array((cp * ct, -sp, cp * st, sp * ct, cp, sp * st, -st, 0.0, ct))
        return m.reshape((t if t.ndim >= p.ndim else p).shape + (3, 3))  # one element: the longer shape
    ct, st, cp, sp = np.cos(t), np.sin(t), np.cos(p), np.sin(p)
    m = np.empty(np.broadcast(t, p).shape + (3, 3))
    m[..., 0, 0], m[..., 0, 1], m[..., 0, 2] = cp * ct, -sp, cp * st
    m[..., 1, 0], m[..., 1, 1], m[..., 1, 2] = sp * ct, cp, sp * st
    m[..., 2, 0], m[..., 2, 1], m[..., 2, 2] = -st, 0.0, ct
    return m


def view_rotation_derivatives(theta, phi):
    """d/dtheta and d/dphi of view_rotation, shape (..., 2, 3, 3)."""
    t, p = np.asarray(theta, dtype=np.float64), np.asarray(phi, dtype=np.float64)
    ct, st, cp, sp = np.cos(t), np.sin(t), np.cos(p), np.sin(p)
    m = np.zeros(np.broadcast(t, p).shape + (2, 3, 3))
    m[..., 0, 0, 0], m[..., 0, 0, 2] = -cp * st, cp * ct      # Rz(phi) dRy/dtheta
    m[..., 0, 1, 0], m[..., 0, 1, 2] = -sp * st, sp * ct
    m[..., 0, 2, 0], m[..., 0, 2, 2] = -ct, -st
    m[..., 1, 0, 0], m[..., 1, 0, 1], m[..., 1, 0, 2] = -sp * ct, -cp, -sp * st   # dRz/dphi Ry(theta)
    m[..., 1, 1, 0], m[..., 1, 1, 1], m[..., 1, 1, 2] = cp * ct, -sp, cp * st
    return m


def camera_position(theta, phi, radius=1.0):
    """(..., 3) Cartesian camera position of view (theta, phi) on a sphere of `radius`."""
    t, p = np.asarray(theta, dtype=np.float64), np.asarray(phi, dtype=np.float64)
    return radius * np.stack([np.sin(t) * np.cos(p), np.sin(t) * np.sin(p), np.cos(t)], -1)


def unit_position(views):
    """Torch views (..., 2) as (theta, phi) -> unit camera positions (..., 3), differentiable."""
    import torch
    t, p = views.unbind(-1)
    return torch.stack([t.sin() * p.cos(), t.sin() * p.sin(), t.cos()], -1)


def camera_axes(theta, phi):
    """(forward, up, right) unit vectors, each (..., 3), of the camera at view (theta, phi)."""
    rot = view_rotation(theta, phi)
    return -rot[..., :, 2], rot[..., :, 0], -rot[..., :, 1]


def optical_rotation(theta, phi):
    """(..., 3, 3) rotation whose columns are the ROS optical axes (x right, y down, z forward)."""
    fwd, up, right = camera_axes(theta, phi)
    return np.stack([right, -up, fwd], -1)


def upright_optical_rotation(theta, phi):
    """(..., 3, 3) optical rotation of view (theta, phi) with the image upright in the object
    frame: optical_rotation turned 180 degrees about the optical axis, so the optical y axis
    (image down) has z = -sin(theta) < 0 and x is level. What a robot is asked for: the model's
    own camera (optical_rotation) sees a level view upside down, and an arm following it would
    roll its wrist half a turn. At the poles, where "up" leaves the image, the roll is this
    formula's limit along the meridian phi: from straight above (theta = 0) image down points
    along +(cos phi, sin phi, 0), from straight below (theta = pi) along -(cos phi, sin phi, 0).
    Any roll reads the same (reprojection.py works from the pose the camera reports)."""
    return optical_rotation(theta, phi) * np.array([-1.0, -1.0, 1.0])


def matrix_to_quaternion(m):
    """Rotation matrix (3, 3) -> quaternion (x, y, z, w), ROS order, w >= 0."""
    m = np.asarray(m, dtype=np.float64)
    tr = np.trace(m)
    if tr > 0:
        s = 2.0 * math.sqrt(tr + 1.0)
        q = [(m[2, 1] - m[1, 2]) / s, (m[0, 2] - m[2, 0]) / s, (m[1, 0] - m[0, 1]) / s, s / 4]
    else:
        i = int(np.argmax(np.diag(m)))
        j, k = (i + 1) % 3, (i + 2) % 3
        s = 2.0 * math.sqrt(1.0 + m[i, i] - m[j, j] - m[k, k])
        q = [0.0, 0.0, 0.0, (m[k, j] - m[j, k]) / s]
        q[i] = s / 4
        q[j] = (m[j, i] + m[i, j]) / s
        q[k] = (m[k, i] + m[i, k]) / s
    q = np.array(q)
    return q if q[3] >= 0 else -q


def quaternion_to_matrix(q):
    """Unit quaternion (x, y, z, w) -> rotation matrix (3, 3)."""
    x, y, z, w = np.asarray(q, dtype=np.float64)
    return np.array([
        [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
        [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
        [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]])


def camera_pose(theta, phi, radius=1.0):
    """(position (3,), quaternion (x, y, z, w)) of the optical frame at view (theta, phi)."""
    return camera_position(theta, phi, radius), matrix_to_quaternion(optical_rotation(theta, phi))


def wrap_view(theta, phi):
    """Keep theta in [0, pi] and phi in [-pi, pi): theta past a pole reflects and phi turns by pi.

    The camera position is unchanged by the wrap (the image turns by 180 degrees about its axis).
    Works on floats, numpy arrays and torch tensors (differentiably: a reflection flips the sign
    of d theta).
    """
    two_pi = 2 * math.pi
    t = theta % two_pi
    flip = t > math.pi
    if hasattr(theta, "detach"):  # torch
        import torch
        t = torch.where(flip, two_pi - t, t)
        p = phi + flip.to(phi.dtype) * math.pi
    else:
        t = np.where(flip, two_pi - t, t)
        p = np.asarray(phi) + np.where(flip, math.pi, 0.0)
    p = (p + math.pi) % two_pi - math.pi
    if np.ndim(t) == 0 and not hasattr(t, "detach"):
        return float(t), float(p)
    return t, p


def view_from_position(position):
    """Cartesian camera position (3,) -> (radius, theta, phi)."""
    x, y, z = np.asarray(position, dtype=np.float64)
    r = math.sqrt(x * x + y * y + z * z)
    if r == 0:
        raise InputError("a camera at the object's centre has no view direction")
    return r, math.acos(max(-1.0, min(1.0, z / r))), math.atan2(y, x)


def default_fov(radius):
    """Field of view (radians) holding the bounding sphere of [-0.5, 0.5]^3 from `radius`.

    Capped at 120 degrees; inside that sphere (radius < 0.87) the shape is clipped, as in the paper.
    """
    return 2 * math.asin(min(1.0, CUBE_RADIUS / radius, math.sin(math.radians(60))))


def pixel_grid(height, width, fov, focal=1.0):
    """Projection-plane coordinates of the pixel centres: x along up, y along right, (H, W) each.

    x = (u0 - u) dx for row u and y = (v - v0) dy for column v, the principal point at the image
    centre; the horizontal field of view `fov` spans the image width.
    """
    d = 2 * focal * math.tan(fov / 2) / width
    u0, v0 = (height - 1) / 2, (width - 1) / 2
    rows, cols = np.meshgrid(np.arange(height), np.arange(width), indexing="ij")
    return (u0 - rows) * d, (cols - v0) * d


@dataclass(frozen=True)
class Intrinsics:
    """A rectified pinhole camera: image size and the K of its CameraInfo, in pixels."""

    width: int
    height: int
    fx: float
    fy: float
    cx: float
    cy: float

    def __post_init__(self):
        if not (1 <= self.width <= 4096 and 1 <= self.height <= 4096):
            raise InputError(f"camera size {self.width}x{self.height} must be 1..4096 pixels a side")
        for name in ("fx", "fy", "cx", "cy"):
            value, focal = getattr(self, name), name in ("fx", "fy")
            if not math.isfinite(value) or (focal and value <= 0):
                kind = "a positive" if focal else "a finite"
                raise InputError(f"camera {name} must be {kind} number of pixels, got {value}")

    @classmethod
    def from_fov(cls, width, height, fov):
        """Square pixels, principal point at the centre, horizontal field of view `fov` (radians)."""
        if not 0 < fov < math.pi:
            raise InputError(f"field of view must lie in (0, 180) degrees, got {math.degrees(fov)}")
        f = width / (2 * math.tan(fov / 2))
        return cls(int(width), int(height), f, f, (width - 1) / 2, (height - 1) / 2)

    def half_fov(self):
        """Half-angle (radians) of the narrower field of view, measured to the nearest image edge."""
        x = min(self.cx + 0.5, self.width - 0.5 - self.cx) / self.fx
        y = min(self.cy + 0.5, self.height - 0.5 - self.cy) / self.fy
        if min(x, y) <= 0:
            raise InputError("the principal point lies outside the image")
        return math.atan(min(x, y))

    def rays(self):
        """(H, W, 3) optical-frame directions (x right, y down, z forward) with z = 1; shared,
        read-only (one camera's rays are built once)."""
        return _rays(self)


@lru_cache(maxsize=8)
def _rays(k):
    rows, cols = np.meshgrid(np.arange(k.height), np.arange(k.width), indexing="ij")
    out = np.stack([(cols - k.cx) / k.fx, (rows - k.cy) / k.fy, np.ones(rows.shape)], -1)
    out.flags.writeable = False
    return out


def random_views(rng, n):
    """n views uniform on the sphere, (n, 2) as (theta, phi), from a numpy Generator."""
    return np.stack([np.arccos(rng.uniform(-1, 1, n)), rng.uniform(-math.pi, math.pi, n)], -1)


def fibonacci_views(n=50):
    """n views evenly spread on the sphere (golden-angle spiral), (n, 2) as (theta, phi)."""
    i = np.arange(n) + 0.5
    theta = np.arccos(1 - 2 * i / n)
    phi = (i * math.pi * (3 - math.sqrt(5))) % (2 * math.pi) - math.pi
    return np.stack([theta, phi], -1)


def straight_path(theta, phi, steps, step_angle=math.radians(30)):
    """Views along the great circle through (theta, phi) heading along +phi at the equator.

    Returns (steps, 2); the first row is the starting view. A camera walks its own "right" axis,
    so the path is a straight line on the sphere whatever the starting view (poles included).
    """
    pos = camera_position(theta, phi)
    _, _, right = camera_axes(theta, phi)
    angles = np.arange(steps) * step_angle
    pts = np.cos(angles)[:, None] * pos + np.sin(angles)[:, None] * right
    views = [view_from_position(p)[1:] for p in pts]
    return np.array(views)


def rotation_from_optical(optical):
    """ROS optical-frame rotation (columns x right, y down, z forward) -> the view rotation
    (columns up, -right, -forward) that maps the t = 0 camera frame to world."""
    o = np.asarray(optical, dtype=np.float64)
    return np.stack([-o[:, 1], -o[:, 0], -o[:, 2]], -1)


def moved(position, rotation, frame):
    """A pose (position (3,), rotation (3, 3)) given in a frame whose own pose in its parent is
    `frame` = (position, rotation): the same pose in the parent."""
    t, r = frame
    return r @ np.asarray(position, dtype=np.float64) + t, r @ rotation


def inverse(frame):
    """The pose (position, rotation) of a frame's parent in the frame."""
    t, r = frame
    return -r.T @ t, r.T


def travel(views):
    """Radians a camera turns about the object's centre along views (N, 2) (theta, phi), each
    move along the great circle: the sum of the angles between successive views."""
    p = camera_position(*np.asarray(views, dtype=np.float64).reshape(-1, 2).T)
    return float(np.sum(angle_between(p[1:], p[:-1])))


def angles_to(views, targets):
    """(B, K) great-circle angles (radians) from each view (B, 2) to each target view (K, 2)."""
    a, b = (camera_position(*np.asarray(v, dtype=np.float64).reshape(-1, 2).T) for v in (views, targets))
    return angle_between(a[:, None], b[None])


def angle_between(a, b):
    """The angles (radians) between unit vectors a and b (..., 3), broadcast: atan2 of |a x b| and
    a . b, exact for small angles, where arccos of a near-1 cosine is not."""
    return np.arctan2(np.linalg.norm(np.cross(a, b), axis=-1), np.sum(a * b, axis=-1))
