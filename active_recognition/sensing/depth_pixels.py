# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""Pixel-level passes over a depth image (inf = no return), for the reprojection: filling the
holes inside surfaces, spreading depths into their neighbourhood, and the z-buffer that keeps
each pixel's nearest point. Each touches only the pixels it must (holes beside known pixels,
running minima), so a frame cropped to the object costs what its object costs."""
from __future__ import annotations

import numpy as np


# the 8 neighbours of a pixel (row, column steps); i and i + 4 are opposite
NEIGHBOURS = ((-1, 0), (0, -1), (-1, -1), (-1, 1), (1, 0), (0, 1), (1, 1), (1, -1))


FILL_ITERATIONS = 4


MAX_SPREAD = 32  # pixels


def fill_holes(z, fillable=None, iterations=FILL_ITERATIONS, agree=0.05, across_jumps=False):
    """Fill missing pixels (inf) that lie inside a surface: between two opposite neighbours whose
    depths agree within `agree` x depth (their mean), or with 3 or 4 of the 4 direct neighbours
    present and agreeing within `agree` x the nearest (their median). Neither rule grows a
    silhouette: a pixel outside an edge, a corner or a staircase has at most 2 direct neighbours;
    nor bridges a depth jump (an object before a floor): a median of both sides would put back,
    mid-air, the flying pixel a camera's filter removed. `across_jumps`: the median of 3 or 4
    whatever their depths, for pixels no ray sampled (a sparse camera's), where a value between
    two surfaces is nearer the truth than a hole. Only `fillable` pixels (default all) change.
    The first round looks only at holes either rule could fill (two opposite neighbours, or 3
    of the 4 direct ones, present), later rounds only at those beside a pixel the round before
    filled."""
    z = np.array(z, dtype=np.float64)
    h, w = z.shape
    pad = np.full((h + 2, w + 2), np.nan)
    inner = pad[1:-1, 1:-1]
    inner[...] = z
    finite = np.isfinite(inner)
    inner[~finite] = np.nan
    holes = np.zeros((h + 2, w + 2), bool)  # the holes that may be filled, padded
    holes[1:-1, 1:-1] = ~finite if fillable is None else ~finite & fillable
    known = np.zeros((h + 2, w + 2), bool)
    known[1:-1, 1:-1] = finite
    nbk = [known[1 + dr:1 + dr + h, 1 + dc:1 + dc + w] for dr, dc in NEIGHBOURS]
    # a hole the first round can fill: two opposite neighbours, or 3 of the 4 direct ones
    can = (nbk[0] & nbk[4]) | (nbk[1] & nbk[5]) | (nbk[2] & nbk[6]) | (nbk[3] & nbk[7])
    can |= (nbk[0].view(np.uint8) + nbk[1] + nbk[4] + nbk[5]) >= 3
    flat, holes = pad.ravel(), holes.ravel()
    offsets = np.array([dr * (w + 2) + dc for dr, dc in NEIGHBOURS])[:, None]
    at = np.flatnonzero(holes.reshape(h + 2, w + 2)[1:-1, 1:-1] & can)
    at = (at // w + 1) * (w + 2) + at % w + 1  # padded
    filled_all = []
    for _ in range(iterations):
        if len(at) == 0:
            break
        nb = flat[at + offsets]  # (8, M)
        a, b = nb[:4], nb[4:]
        with np.errstate(invalid="ignore"):
            gap = np.abs(a - b)
            agreeing = gap <= agree * np.fmin(a, b)
        pair = agreeing.any(0)
        direct = nb[[0, 1, 4, 5]]
        one_surface = across_jumps | (np.fmax.reduce(direct, 0) <= (1 + agree) * np.fmin.reduce(direct, 0))
        crowd = (np.isnan(direct).sum(0) <= 1) & ~pair & one_surface
        done = pair | crowd
        if not done.any():
            break
        gap[~agreeing] = np.inf
        column = np.arange(len(at))
        best = np.argmin(gap, 0)
        value = (a[best, column] + b[best, column]) / 2
        if crowd.any():
            ordered = np.sort(direct[:, crowd], 0)  # NaN last: the median of 3 or of 4
            four = ~np.isnan(ordered[3])
            value[crowd] = np.where(four, (ordered[1] + ordered[2]) / 2, ordered[1])
        filled = at[done]
        flat[filled] = value[done]
        holes[filled] = False
        filled_all.append(filled)
        near = np.zeros(flat.size, bool)  # the holes beside them, each once
        near[(filled + offsets).ravel()] = True
        at = np.flatnonzero(near & holes)
    if filled_all:
        filled = np.concatenate(filled_all)
        z.ravel()[(filled // (w + 2) - 1) * w + filled % (w + 2) - 1] = flat[filled]
    return z


def _ordered_bits(x):
    """float32 -> int64 in [0, 2^32) in the floats' order (the inverse: _from_ordered_bits)."""
    bits = x.view(np.int32).astype(np.int64)
    return np.where(bits < 0, -(bits & 0x7FFFFFFF), bits) + 2 ** 31


def _from_ordered_bits(key):
    key = key - 2 ** 31
    bits = np.where(key < 0, -key | 0x80000000, key).astype(np.uint32)
    return bits.view(np.float32)


RING_STEPS = 6  # up to so many steps, spread grows ring by ring; beyond, one distance transform


def spread(z, steps):
    """Each missing pixel (NaN) takes the depth of a present pixel within `steps` pixels (4-way
    steps, the nearest first, the smallest among equally near ones), at float32 precision;
    farther ones stay NaN.

    A few steps (the usual: a model pixel and one more) grow ring by ring, each missing pixel
    beside the last ring taking the least of its 4 neighbours (a 4-way path to the nearest present
    pixels passes only through missing pixels one step nearer). More steps take a city-block
    distance transform, exact: the distance and the depth ride in one integer key, minimised with
    running minima down and up the columns, then along the rows (a 4-way path can always go along
    a column first)."""
    z = np.array(z, dtype=np.float64)
    missing = np.isnan(z)
    if steps <= 0 or missing.all() or not missing.any():
        return z
    if steps <= RING_STEPS:
        pad = np.full((z.shape[0] + 2, z.shape[1] + 2), np.nan)
        inner = pad[1:-1, 1:-1]
        inner[...] = z.astype(np.float32)
        for _ in range(steps):
            near = np.fmin(np.fmin(pad[:-2, 1:-1], pad[2:, 1:-1]), np.fmin(pad[1:-1, :-2], pad[1:-1, 2:]))
            ring = np.isnan(inner) & ~np.isnan(near)
            if not ring.any():
                break
            inner[ring] = near[ring]
        z[missing] = inner[missing]
        return z
    depth = _ordered_bits(np.where(missing, 0, z).astype(np.float32))
    key = np.where(missing, np.int64(2) ** 62, depth)  # distance << 32 | depth
    for axis in (0, 1):
        ramp = np.arange(key.shape[axis], dtype=np.int64) << 32
        ramp = ramp[:, None] if axis == 0 else ramp[None, :]
        down = np.minimum.accumulate(key - ramp, axis=axis) + ramp
        up = np.flip(np.minimum.accumulate(np.flip(key + ramp, axis), axis=axis), axis) - ramp
        key = np.minimum(down, up)
    reach = missing & ((key >> 32) <= steps)
    z[reach] = _from_ordered_bits(key[reach] & 0xFFFFFFFF)
    return z


def z_buffer(index, z, size, surface=0.1):
    """Per pixel the depth of the nearest surface among the depths z landing on it (pixel indices
    `index`): the mean of those within `surface` of the nearest; inf where none lands."""
    near = np.full(size, np.inf)
    np.minimum.at(near, index, z)
    front = z <= near[index] + surface
    count = np.bincount(index[front], minlength=size)
    mean = np.bincount(index[front], z[front], minlength=size) / np.maximum(count, 1)
    return np.where(count > 0, mean, np.inf)
