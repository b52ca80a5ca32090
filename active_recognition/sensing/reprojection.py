# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""Any depth camera -> the model's virtual camera: back-project, crop to the object, re-render.

A real camera has its own lens, resolution, distance and pose, and sees the floor under the
object. The network only knows its own camera: radius R on the viewing sphere, its field of
view, the object scaled into [-0.5, 0.5]^3. `reproject` closes that gap with geometry alone:
1. back-project the valid pixels with K into the optical frame, move them into the object frame
   with the camera's pose;
2. scale by 1/object_size and keep the points inside the object's box (plus `box_margin`), so
   walls and other objects never reach the network; the support surface the object stands on
   lies on the box's bottom face, so it is found (`support_height`) and cut off as well;
3. z-buffer the points into the model's image at the actual view direction (the theta, phi of
   the camera's position), fill small holes, normalise to [0, 255].
Speed (a camera's 30 Hz at 640x480 or 1280x720): every pass over pixels but one works on the
crop, the object's box projected into the image; the one (a floor beside the object) reads a
single coordinate of the pixels around the box. A `Frame` is back-projected once, and `kept`
and `render` redo only the per-centre part, so re-centring the object reuses the points.
No ROS here: the recognizer node only wires messages to it.
"""
from __future__ import annotations

import itertools
import math
from dataclasses import dataclass

import numpy as np

from active_recognition.argument_checks import InputError
from active_recognition.sensing import geometry
from active_recognition.sensing.depth_layer import CameraConfig, normalise_depth
from active_recognition.sensing.depth_pixels import FILL_ITERATIONS, MAX_SPREAD, fill_holes, spread, z_buffer

STANDOFF_MARGIN = 1.1  # the auto standoff leaves 10 % around the object's bounding sphere


def auto_standoff(k: geometry.Intrinsics, object_size=1.0, margin=STANDOFF_MARGIN):
    """Distance (metres) at which the object's bounding sphere (the box of edge `object_size`)
    fills the narrower field of view of `k`, with `margin` to spare."""
    return margin * geometry.CUBE_RADIUS * object_size / math.sin(k.half_fov())


def support_height(points, box_margin=0.1, bin_width=0.02):
    """The height of the surface the object stands on, or None when none is seen.

    points: (N, 3) in the normalised object frame. Points beside the object's footprint (outside
    the box in x or y) but low in the box cannot be the object: a floor or table top is the
    lowest dense layer among them. Returns (height, thickness): cut below height + thickness.
    """
    beside = np.maximum(np.abs(points[:, 0]), np.abs(points[:, 1]))
    out = points[(beside > 0.5 + box_margin) & (beside < 1.5)
                 & (points[:, 2] > -0.5 - box_margin - bin_width) & (points[:, 2] < 0.0)]
    if len(out) < 8:
        return None
    counts, edges = np.histogram(out[:, 2], np.arange(out[:, 2].min(), 0.0 + bin_width, bin_width))
    dense = np.nonzero(counts >= max(8, 0.25 * len(out)))[0]
    if len(dense) == 0:
        return None
    lo = edges[dense[0]] - bin_width
    layer = out[(out[:, 2] >= lo) & (out[:, 2] < edges[dense[0]] + 2 * bin_width), 2]
    height = float(np.median(layer))
    spread = float(np.median(np.abs(layer - height))) * 1.4826  # robust standard deviation
    return height, max(bin_width, 4 * spread)


def seen_centre(points, position, oblique=0.8, stray=0.005):
    """The centre of the object's box, from the points one view saw of it, along the object's
    axes that the view sees the whole extent of.

    From a view off an axis the object's extremes along that axis lie on its silhouette or face
    the camera, so the middle of the seen points' extent is the box's centre along it. Along an
    axis within acos(`oblique`) of the line of sight the far side is hidden: that component stays
    0. The extent leaves out the `stray` share of the points at each end: a few points of a far,
    noisy floor left above the support's cut would otherwise stretch it to the box's edge.
    points (N, 3) and the camera position (3,), normalised object frame; returns (3,).
    """
    d = np.asarray(position, dtype=np.float64)
    d = np.abs(d) / np.linalg.norm(d)
    points = np.asarray(points, dtype=np.float64)
    lo, hi = np.quantile(points, [stray, 1 - stray], axis=0)
    return np.where(d < oblique, (lo + hi) / 2, 0.0)


RAYS_PER_PIXEL = 2  # at least so many rays of a large image across a model pixel (Frame)


def box_pixels(lo, hi, k: geometry.Intrinsics, position, rotation, size, pad=0):
    """(r0, r1, c0, c1): the image rows and columns that can see the box lo..hi (normalised
    object frame), `pad` pixels around; the whole image when the box reaches behind the camera,
    none when it lies wholly behind."""
    corners = np.array(list(itertools.product(*zip(lo, hi))), dtype=np.float64)
    cam = (corners - position) * size @ rotation  # (8, 3) optical frame, metres
    front = cam[:, 2] > 1e-6
    if not front.any():
        return 0, 0, 0, 0
    if not front.all():
        return 0, k.height, 0, k.width
    u = k.cx + k.fx * cam[:, 0] / cam[:, 2]
    v = k.cy + k.fy * cam[:, 1] / cam[:, 2]
    r0, r1 = max(0, math.floor(v.min()) - pad), min(k.height, math.ceil(v.max()) + 1 + pad)
    c0, c1 = max(0, math.floor(u.min()) - pad), min(k.width, math.ceil(u.max()) + 1 + pad)
    return (r0, r1, c0, c1) if r0 < r1 and c0 < c1 else (0, 0, 0, 0)


@dataclass
class Reprojection:
    depth: np.ndarray       # (H, W) the network's input, normalised depth in [0, 255]
    view: tuple             # (theta, phi) of the actual camera position
    object_fraction: float  # share of the model's pixels that show the object
    support: tuple | None   # (height, thickness) of the support surface removed, normalised
    points: np.ndarray      # (N, 3) the object's points kept, in the normalised object frame
    cut: bool               # the object's points reach the image's edge (it may be cut off)


@dataclass
class Kept:
    """A frame's pixels inside the object's box about one centre, and where they land."""

    offset: np.ndarray      # (3,) that centre, normalised, from the frame's
    keep: np.ndarray        # (h, w) over the crop
    support: tuple | None
    points: np.ndarray      # (N, 3) about that centre
    cut: bool
    view: tuple
    index: np.ndarray       # model pixel of each point that lands on the model's image
    depth: np.ndarray       # and its z-depth there
    count: np.ndarray       # (H * W,) points per model pixel

    @property
    def most(self):
        """An upper bound of the Reprojection's object_fraction."""
        return float((self.count > 0).mean())


class Frame:
    """A real depth image back-projected once (`reproject` in steps).

    metres (H, W) z-depth; k its intrinsics; position (3,) metres and optical_rotation (3, 3)
    (columns x right, y down, z forward) of the camera in the object frame; camera the model's.
    `reach` (normalised): how far from the given centre `kept` may later be asked to look.
    `stride`: read every stride-th row and column (None: as many as leave at least
    RAYS_PER_PIXEL rays across each of the model's pixels; 1: every pixel).
    """

    def __init__(self, metres, k: geometry.Intrinsics, position, optical_rotation,
                 camera: CameraConfig, object_size=1.0, box_margin=0.1, fill=True, reach=0.0,
                 stride=None):
        if not (math.isfinite(object_size) and object_size > 0):
            raise InputError(f"object_size must be a positive number of metres, got {object_size}")
        z = np.asarray(metres)
        if z.shape != (k.height, k.width):
            raise InputError(f"depth image is {z.shape[1]}x{z.shape[0]} but the camera info says "
                             f"{k.width}x{k.height}")
        self.k, self.camera, self.size, self.margin = k, camera, object_size, box_margin
        self.model_k = camera.intrinsics()
        self.position = np.asarray(position, dtype=np.float64) / object_size
        self.rotation = np.asarray(optical_rotation, dtype=np.float64)
        s = self.stride = stride or max(1, int(self.ratio() / RAYS_PER_PIXEL))
        # the crop: pixels that may show the box about any centre within reach, or lie within the
        # spread of one that does; on the grid of every s-th row and column of the image
        half = 0.5 + box_margin + reach
        r0, r1, c0, c1 = box_pixels((-half,) * 3, (half,) * 3, k, self.position, self.rotation,
                                    object_size, s * (self.spread_steps(reach) + 1))
        self.crop = r0, r1, c0, c1 = r0 - r0 % s, r1, c0 - c0 % s, c1
        # its depth, holes filled from FILL_ITERATIONS pixels around (as a whole-frame fill)
        f = s * FILL_ITERATIONS if fill else 0
        f0, g0 = max(0, r0 - f), max(0, c0 - f)
        near = np.asarray(z[f0:min(k.height, r1 + f):s, g0:min(k.width, c1 + f):s], np.float64)
        near = np.where(np.isfinite(near) & (near > 0), near, np.inf)
        if fill:  # pixels lost inside surfaces (dropout, flying pixels): fill them where they are
            near = fill_holes(near)
        rows, cols = np.arange(r0, r1, s), np.arange(c0, c1, s)
        self.z = near[(r0 - f0) // s:, (c0 - g0) // s:][:len(rows), :len(cols)]  # inf = none
        self.valid = np.isfinite(self.z)
        self.u, self.v = (cols - k.cx) / k.fx, (rows - k.cy) / k.fy  # the crop's rays: (u, v, 1)
        with np.errstate(invalid="ignore"):  # inf x 0 on a ray's zero component
            self.xyz = [self.along(j, self.z, self.v[:, None], self.u[None, :]) for j in range(3)]
        # does the crop meet the image's top, bottom, left, right edge?
        self.edges = (r0 == 0, len(rows) and rows[-1] + s >= k.height,
                      c0 == 0, len(cols) and cols[-1] + s >= k.width)
        self.beside = self.support_candidates(z, reach)

    def along(self, j, depth, v, u):
        """Coordinate j (normalised object frame) of the rays (u, v, 1) at z-depth `depth`."""
        r = self.rotation[j] / self.size
        return (r[0] * u + r[1] * v + r[2]) * depth + self.position[j]

    def centre_depth(self, offset=np.zeros(3)):
        """z-depth (metres) of the object's centre (at `offset` from the given one), >= 1e-6."""
        return max(float((offset - self.position) @ self.rotation[:, 2]) * self.size, 1e-6)

    def ratio(self, depth=None):
        """This camera's pixels per model pixel, at the object's distance (or `depth` metres)."""
        depth = self.centre_depth() if depth is None else depth
        model = self.model_k.fx / self.camera.radius
        return self.k.fx / (depth / self.size) / model

    def spread_steps(self, reach=0.0, offset=np.zeros(3)):
        """How far (pixels of the image) a missing ray takes the depth of the object beside it:
        a model pixel wide and then one more, at the object's distance."""
        depth = max(self.centre_depth(offset) - reach * self.size, 1e-6)
        return int(min(MAX_SPREAD, math.ceil(2 * self.ratio(depth))))

    def support_candidates(self, z, reach, eps=1e-3):
        """(M, 3) the valid points that may lie beside the box, low in it (support_height's
        search) about any centre within reach: one coordinate of the pixels that can see that
        region (float32), all three of the few that pass."""
        lo, hi = -0.5 - self.margin - 0.02 - reach - eps, reach + eps  # 0.02: support's bin
        ring, s = 1.5 + reach + eps, self.stride
        k, (r0, r1, c0, c1) = self.k, self.crop
        s0, s1, t0, t1 = box_pixels((-ring, -ring, lo), (ring, ring, hi), k, self.position,
                                    self.rotation, self.size)
        s0, t0 = s0 - s0 % s, t0 - t0 % s  # the crop's grid
        raw = np.asarray(z[s0:s1:s, t0:t1:s], dtype=np.float32)
        u = ((np.arange(t0, t1, s) - k.cx) / k.fx).astype(np.float32)
        v = ((np.arange(s0, s1, s) - k.cy) / k.fy).astype(np.float32)
        r = self.rotation[2].astype(np.float32)
        with np.errstate(invalid="ignore"):
            height = ((r[0] * u)[None, :] + (r[1] * v + r[2])[:, None]) * raw  # metres, NaN = none
            near = (height > (lo - self.position[2]) * self.size) & \
                (height < (hi - self.position[2]) * self.size) & (raw > 0)
        if r0 < r1 and c0 < c1:  # the crop's own come from its filled depth
            near[max(r0 - s0, 0) // s:max(r1 - s0, 0) // s + 1,
                 max(c0 - t0, 0) // s:max(c1 - t0, 0) // s + 1] = False
        rows, cols = np.nonzero(near)
        rows, cols = rows * s + s0, cols * s + t0
        depth = np.asarray(z[rows, cols], dtype=np.float64)
        out = np.stack([self.along(j, depth, (rows - k.cy) / k.fy, (cols - k.cx) / k.fx)
                        for j in range(3)], 1)
        inside = np.stack([c[self.valid] for c in self.xyz], 1)
        out = np.concatenate([out, inside[(inside[:, 2] > lo) & (inside[:, 2] < hi)]])
        beside = np.maximum(np.abs(out[:, 0]), np.abs(out[:, 1]))
        return out[(beside > 0.5 + self.margin - reach - eps) & (beside < ring)]

    def kept(self, offset=np.zeros(3)) -> Kept:
        """The points inside the object's box about the centre at `offset` (normalised, within
        the frame's reach of the given centre), the support under it cut off."""
        offset = np.asarray(offset, dtype=np.float64)
        x, y, z = (c - o for c, o in zip(self.xyz, offset))
        half = 0.5 + self.margin
        with np.errstate(invalid="ignore"):
            keep = (np.abs(x) <= half) & (np.abs(y) <= half) & (np.abs(z) <= half)
        support = support_height(self.beside - offset, self.margin) if len(self.beside) else None
        position = self.position - offset
        if support is not None and position[2] > support[0]:  # a support is only seen from above
            keep &= z > support[0] + support[1]
        rows, cols = np.nonzero(keep)
        points = np.stack([x[rows, cols], y[rows, cols], z[rows, cols]], 1)
        top, bottom, left, right = self.edges
        cut = bool((top and keep[:1].any()) or (bottom and keep[-1:].any())
                   or (left and keep[:, :1].any()) or (right and keep[:, -1:].any()))
        _, theta, phi = geometry.view_from_position(position)
        index, depth = self.land(self.z[rows, cols], self.v[rows], self.u[cols], (theta, phi),
                                 offset)
        count = np.bincount(index, minlength=self.camera.height * self.camera.width)
        return Kept(offset, keep, support, points, cut, (theta, phi), index, depth, count)

    def land(self, depth, v, u, view, offset):
        """Rays (u, v, 1) at z-depth `depth` -> (model pixel index (M,), z-depth (M,)) in the
        model's camera at `view` about the centre at `offset`; points behind it or off it drop."""
        rot = geometry.view_rotation(*view)  # t = 0 frame: up +X, right -Y, fwd -Z
        m = self.rotation.T @ rot / self.size
        t = (self.position - offset - rot[:, 2] * self.camera.radius) @ rot
        local = [(m[0, j] * u + m[1, j] * v + m[2, j]) * depth + t[j] for j in range(3)]
        z = -local[2]
        front = z > 1e-6
        k, cam = self.model_k, self.camera
        z, up, right = z[front], local[0][front], local[1][front]
        col = np.rint(k.cx - k.fx * right / z).astype(np.int64)  # right = -Y
        row = np.rint(k.cy - k.fy * up / z).astype(np.int64)  # down = -up
        inside = (row >= 0) & (row < cam.height) & (col >= 0) & (col < cam.width)
        return row[inside] * cam.width + col[inside], z[inside]

    def render(self, kept: Kept, fill=True) -> Reprojection:
        """The model's image of the points `kept` (module docstring, step 3)."""
        # A pixel shows the object when most of the rays through it hit the object: the render's
        # rule (one ray, through the centre), with no half-pixel growth from a dense camera. Rays
        # that missed the object count where they pass it: at the depth of the object beside them.
        n = self.camera.height * self.camera.width
        centre = self.centre_depth(kept.offset)
        steps = -(-self.spread_steps(0.0, kept.offset) // self.stride)  # on the crop's grid
        beside = spread(np.where(kept.keep, self.z, np.nan), steps)
        own = np.where(self.valid, self.z, centre)  # a ray's own depth, or the object's centre's
        beside = np.where(kept.keep | np.isnan(beside), own, beside)
        with np.errstate(invalid="ignore"):
            rays = self.land(beside, self.v[:, None], self.u[None, :], kept.view, kept.offset)[0]
        samples = np.bincount(rays, minlength=n)
        out = z_buffer(kept.index, kept.depth, n)
        out[kept.count < 0.5 * samples] = np.inf
        out = out.reshape(self.camera.height, self.camera.width)
        found = float(np.isfinite(out).mean())
        missed = samples.reshape(out.shape) == 0
        if fill and missed.any():  # pixels no ray passed through: a camera farther off
            out = fill_holes(out, missed, across_jumps=True)
        return Reprojection(normalise_depth(out, self.camera), kept.view, found, kept.support,
                            kept.points, kept.cut)


def reproject(metres, k: geometry.Intrinsics, position, optical_rotation, camera: CameraConfig,
              object_size=1.0, box_margin=0.1, fill=True, stride=None) -> Reprojection:
    """A real depth image -> the model's image at the camera's actual view (module docstring).

    metres (H, W) z-depth; k its intrinsics; position (3,) metres and optical_rotation (3, 3)
    (columns x right, y down, z forward) of the camera in the object frame; camera the model's.
    Only the pixels that can see the object's box are read whole (`Frame`, also for `stride`).
    """
    frame = Frame(metres, k, position, optical_rotation, camera, object_size, box_margin, fill,
                  stride=stride)
    return frame.render(frame.kept(), fill)
