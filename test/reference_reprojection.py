# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""The reprojection as it was before the crop (commit 1c63c4d), kept as the reference the fast
path is tested against: every pass over the whole frame, in plain loops over neighbours.

Only the functions the tests compare are kept: fill_holes, spread and reproject (with the
helpers it calls from the package, which are unchanged).
"""
from __future__ import annotations

import math

import numpy as np

from active_recognition.argument_checks import InputError
from active_recognition.sensing import geometry
from active_recognition.sensing.depth_layer import CameraConfig, normalise_depth
from active_recognition.sensing.reprojection import Reprojection, support_height


def fill_holes(z, fillable=None, iterations=4, agree=0.05, across_jumps=False):
    """Fill missing pixels (inf) that lie inside a surface: between two opposite neighbours whose
    depths agree within `agree` x depth (their mean), or with 3 or 4 of the 4 direct neighbours
    present and agreeing within `agree` x the nearest (their median). Neither rule grows a
    silhouette nor bridges a depth jump. Only `fillable` pixels (default all) change."""
    z = z.copy()
    h, w = z.shape
    for _ in range(iterations):
        holes = ~np.isfinite(z) if fillable is None else ~np.isfinite(z) & fillable
        if not holes.any():
            break
        pad = np.pad(np.where(np.isfinite(z), z, np.nan), 1, constant_values=np.nan)
        nb = np.stack([pad[1 + dr:1 + dr + h, 1 + dc:1 + dc + w]
                       for dr, dc in ((-1, 0), (0, -1), (-1, -1), (-1, 1),
                                      (1, 0), (0, 1), (1, 1), (1, -1))])  # (8, H, W): i, i + 4 opposite
        a, b = nb[:4], nb[4:]
        with np.errstate(invalid="ignore"):
            gap = np.where(np.abs(a - b) <= agree * np.fmin(a, b), np.abs(a - b), np.inf)
        pair = holes & np.isfinite(gap).any(0)
        direct = nb[[0, 1, 4, 5]]
        far = np.where(np.isnan(direct), -np.inf, direct).max(0)
        near = np.where(np.isnan(direct), np.inf, direct).min(0)
        agreeing = across_jumps | (far <= (1 + agree) * near)
        crowd = holes & ~pair & (np.isfinite(direct).sum(0) >= 3) & agreeing
        if not (pair.any() or crowd.any()):
            break
        best = np.argmin(gap, 0)
        mean = (np.take_along_axis(a, best[None], 0)[0] + np.take_along_axis(b, best[None], 0)[0]) / 2
        z[pair] = mean[pair]
        z[crowd] = np.nanmedian(direct[:, crowd], axis=0)
    return z


def spread(z, steps):
    """Each missing pixel (NaN) takes the depth of a present pixel within `steps` pixels (4-way
    steps, the nearest first); farther ones stay NaN."""
    z = z.copy()
    h, w = z.shape
    for _ in range(steps):
        gaps = np.isnan(z)
        if not gaps.any():
            break
        pad = np.pad(z, 1, constant_values=np.nan)
        nb = np.stack([pad[:-2, 1:-1], pad[2:, 1:-1], pad[1:-1, :-2], pad[1:-1, 2:]])
        reach = gaps & ~np.isnan(nb).all(0)
        if not reach.any():
            break
        z[reach] = np.nanmin(nb[:, reach], 0)
    return z


def project(points, view, camera: CameraConfig):
    """Points (N, 3) in the normalised object frame -> (pixel index (M,), z-depth (M,)) in the
    model's camera at view (theta, phi) on its sphere; points behind it or off the image drop."""
    rot = geometry.view_rotation(*view)
    local = (points - rot[:, 2] * camera.radius) @ rot  # t = 0 frame: up +X, right -Y, fwd -Z
    z = -local[:, 2]
    front = z > 1e-6
    local, z = local[front], z[front]
    k = camera.intrinsics()
    col = np.rint(k.cx - k.fx * local[:, 1] / z).astype(np.int64)  # right = -Y
    row = np.rint(k.cy - k.fy * local[:, 0] / z).astype(np.int64)  # down = -up
    inside = (row >= 0) & (row < camera.height) & (col >= 0) & (col < camera.width)
    return row[inside] * camera.width + col[inside], z[inside]


def z_buffer(index, z, size, surface=0.1):
    """Per pixel the depth of the nearest surface among the depths z landing on it (pixel indices
    `index`): the mean of those within `surface` of the nearest; inf where none lands."""
    near = np.full(size, np.inf)
    np.minimum.at(near, index, z)
    front = z <= near[index] + surface
    count = np.bincount(index[front], minlength=size)
    mean = np.bincount(index[front], z[front], minlength=size) / np.maximum(count, 1)
    return np.where(count > 0, mean, np.inf)


def reproject(metres, k: geometry.Intrinsics, position, optical_rotation, camera: CameraConfig,
              object_size=1.0, box_margin=0.1, fill=True) -> Reprojection:
    """A real depth image -> the model's image at the camera's actual view (module docstring).

    metres (H, W) z-depth; k its intrinsics; position (3,) metres and optical_rotation (3, 3)
    (columns x right, y down, z forward) of the camera in the object frame; camera the model's.
    """
    if not (math.isfinite(object_size) and object_size > 0):
        raise InputError(f"object_size must be a positive number of metres, got {object_size}")
    z = np.asarray(metres, dtype=np.float64)
    if z.shape != (k.height, k.width):
        raise InputError(f"depth image is {z.shape[1]}x{z.shape[0]} but the camera info says "
                         f"{k.width}x{k.height}")
    if fill:  # pixels lost inside surfaces (dropout, flying pixels): fill them where they are
        z = fill_holes(np.where(np.isfinite(z) & (z > 0), z, np.inf))
    position = np.asarray(position, dtype=np.float64) / object_size
    rotation = np.asarray(optical_rotation, dtype=np.float64)
    _, theta, phi = geometry.view_from_position(position)
    valid = (np.isfinite(z) & (z > 0)).ravel()
    # every pixel's ray, at its depth, or where it passes the object's centre when it saw nothing
    centre_depth = max(float(-position @ rotation[:, 2]) * object_size, 1e-6)
    depth_all = np.where(valid, z.ravel(), centre_depth)

    def along_rays(depth):  # every pixel's ray at `depth` (metres) -> normalised object frame
        return (k.rays().reshape(-1, 3) * depth[:, None]) @ rotation.T / object_size + position

    pts = along_rays(depth_all)
    support = support_height(pts[valid], box_margin)
    keep = valid & (np.abs(pts) <= 0.5 + box_margin).all(1)
    if support is not None and position[2] > support[0]:  # a support is only seen from above
        keep &= pts[:, 2] > support[0] + support[1]
    # A pixel shows the object when most of the rays through it hit the object: the render's
    # rule (one ray, through the centre), with no half-pixel growth from a dense camera. Rays
    # that missed the object count where they pass it: at the depth of the object beside them.
    n = camera.height * camera.width
    index, depth = project(pts[keep], (theta, phi), camera)
    ratio = (k.fx / (centre_depth / object_size)) / (camera.intrinsics().fx / camera.radius)
    beside = spread(np.where(keep, z.ravel(), np.nan).reshape(z.shape),
                    int(min(32, math.ceil(2 * ratio)))).ravel()
    beside = np.where(keep | np.isnan(beside), depth_all, beside)
    samples = np.bincount(project(along_rays(beside), (theta, phi), camera)[0], minlength=n)
    out = z_buffer(index, depth, n)
    out[np.bincount(index, minlength=n) < 0.5 * samples] = np.inf
    out = out.reshape(camera.height, camera.width)
    found = float(np.isfinite(out).mean())
    if fill:  # pixels no ray passed through: a camera farther off than the model's
        out = fill_holes(out, samples.reshape(out.shape) == 0, across_jumps=True)
    kept = keep.reshape(z.shape)
    cut = bool(kept[:, [0, -1]].any() or kept[[0, -1]].any())
    return Reprojection(normalise_depth(out, camera), (theta, phi), found, support, pts[keep], cut)
