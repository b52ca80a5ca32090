# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""Furniture parts from trimesh's primitives and operations, for the generated benchmarks.

Slabs with sharp, bevelled or rounded edges (shapely outlines, extruded), cushions (squared
spheres), legs of several kinds (square, round, tapered, turned: revolved profiles; splayed),
curved shells (a buffered arc, extruded), plates and discs. `Style` carries what varies
between pieces of one class regardless of its structure: edges, legs, mesh resolution. Units are
metres-like; the shape is normalised into the unit cube afterwards. Deterministic in the rng.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import trimesh
from shapely import affinity
from shapely.geometry import LineString, Point
from shapely.geometry import box as outline

EDGES = ("sharp", "bevel", "round")
LEGS = ("square", "round", "tapered", "turned", "splayed")


@dataclass
class Style:
    edge: str = "sharp"    # of slabs: sharp, bevel or round
    leg: str = "square"    # one of LEGS
    sections: int = 16     # segments around round parts (mesh resolution)
    quad_segs: int = 3     # segments per rounded quarter

    @classmethod
    def draw(cls, rng):
        return cls(edge=EDGES[rng.integers(3)], leg=LEGS[rng.integers(len(LEGS))],
                   sections=int(rng.choice([6, 8, 12, 16, 24, 32])),
                   quad_segs=int(rng.integers(1, 6)))


def box(center, size):
    m = trimesh.creation.box(extents=size)
    m.apply_translation(center)
    return m


def cylinder(center, radius, height, sections=16, axis=2):
    """A cylinder of `height` along `axis` (0, 1, 2) centred at `center`."""
    m = trimesh.creation.cylinder(radius=radius, height=height, sections=sections)
    return place(m, center, axis)


def place(mesh, center, axis=2):
    """Turn a mesh built along z so that z runs along `axis` (a rotation, never a mirror), then
    move it to `center`."""
    a = (axis + 1) % 3, (axis + 2) % 3, axis  # where x, y, z go: cyclic, so det = +1
    m = np.zeros((4, 4))
    m[a[0], 0] = m[a[1], 1] = m[a[2], 2] = m[3, 3] = 1
    mesh.apply_transform(m)
    mesh.apply_translation(center)
    return mesh


def extrude(polygon, height, center, axis=2):
    """Extrude a shapely outline by `height` along `axis`, centred at `center`."""
    m = trimesh.creation.extrude_polygon(polygon, height)
    m.apply_translation((0, 0, -height / 2))
    return place(m, center, axis)


def slab(center, size, style: Style, axis=2, radius=None):
    """A box whose edges parallel to `axis` are sharp, bevelled or rounded (style.edge)."""
    size = np.asarray(size, float)
    if style.edge == "sharp":
        return box(center, size)
    u, v = size[(axis + 1) % 3], size[(axis + 2) % 3]
    r = min(radius if radius is not None else 0.2 * min(u, v), 0.45 * min(u, v))
    core = outline(-u / 2 + r, -v / 2 + r, u / 2 - r, v / 2 - r)
    shape = core.buffer(r, quad_segs=style.quad_segs,
                        join_style="round" if style.edge == "round" else "bevel")
    return extrude(shape, size[axis], center, axis)


def cushion(center, size, squareness=0.5, subdivisions=2):
    """A pillow: a sphere pushed toward a box (squareness 0: ellipsoid, 1: nearly a box)."""
    m = trimesh.creation.icosphere(subdivisions=subdivisions)
    p = 1 - 0.7 * squareness
    m.vertices = np.sign(m.vertices) * np.abs(m.vertices) ** p * np.asarray(size) / 2
    m.apply_translation(center)
    return m


def turned(center, radii, height, sections=16):
    """A revolved profile along z: radii at evenly spaced heights, closed at both ends."""
    z = np.linspace(0, height, len(radii))
    profile = np.column_stack([np.r_[0, radii, 0], np.r_[0, z, height]])
    m = trimesh.creation.revolve(profile, sections=sections)
    m.apply_translation(np.asarray(center) - (0, 0, height / 2))
    return m


def leg(kind, foot, height, thick, style: Style, outward=(0.0, 0.0)):
    """One leg standing on `foot` (x, y, 0) with its top at `height`; `outward` is the
    direction a splayed leg leans toward."""
    x, y = foot
    c = (x, y, height / 2)
    if kind == "square":
        return box(c, (thick, thick, height))
    if kind == "round":
        return cylinder(c, thick / 2, height, style.sections)
    if kind == "tapered":
        return turned(c, [0.3 * thick, thick / 2], height, style.sections)
    if kind == "turned":
        r = thick / 2
        return turned(c, [0.6 * r, r, 0.55 * r, 0.9 * r, 0.5 * r, r, r], height, style.sections)
    m = box((0, 0, height / 2), (thick, thick, height))  # splayed: lean the foot outward 10 deg
    d = np.array([*outward, 0.0])
    d = d / (np.linalg.norm(d) or 1)
    m.apply_transform(trimesh.transformations.rotation_matrix(
        np.radians(10), np.cross((0, 0, 1), d) if d.any() else (1, 0, 0), (0, 0, height)))
    m.apply_translation((x, y, 0))
    return m


def legs4(w, d, height, inset, thick, style: Style, kind=None):
    """Four legs under a w x d top whose underside is at `height`."""
    kind = kind or style.leg
    return [leg(kind, (sx * (w / 2 - inset), sy * (d / 2 - inset)), height, thick, style,
                outward=(sx, sy)) for sx in (-1, 1) for sy in (-1, 1)]


def pedestal(height, radius, base_radius, style: Style, center=(0, 0)):
    """A central column on a round foot."""
    x, y = center
    return [cylinder((x, y, height / 2), radius, height, style.sections),
            cylinder((x, y, 0.015), base_radius, 0.03, style.sections)]


def star_base(height, spread, style: Style, arms=5):
    """An office chair's base: a column on `arms` spokes with castors."""
    parts = [cylinder((0, 0, height / 2 + 0.05), 0.03, height - 0.1, style.sections)]
    for k in range(arms):
        a = 2 * np.pi * k / arms
        spoke = box((spread / 2, 0, 0.08), (spread, 0.05, 0.04))
        spoke.apply_transform(trimesh.transformations.rotation_matrix(a, (0, 0, 1)))
        parts += [spoke, trimesh.creation.icosphere(1, radius=0.03).apply_translation(
            (spread * np.cos(a), spread * np.sin(a), 0.03))]
    return parts


def shell(center, width, height, thick, bulge, axis=2, points=9):
    """A curved panel: an arc across `width` (along x) bulging by `bulge` toward +y, `thick`
    thick, extruded `height` along `axis` (2: an upright back; 1: a seat-like dish)."""
    x = np.linspace(-width / 2, width / 2, points)
    arc = LineString(np.column_stack([x, bulge * (1 - (2 * x / width) ** 2)]))
    return extrude(arc.buffer(thick / 2, cap_style="flat"), height, center, axis)


def plate(center, polygon, thick):
    """A flat plate of a shapely outline (a tub's bottom, a round table top)."""
    return extrude(polygon, thick, center)


def disc(center, radius, thick, style: Style, scale=(1.0, 1.0)):
    """A round or oval plate along z."""
    p = affinity.scale(Point(0, 0).buffer(radius, quad_segs=max(2, style.sections // 4)), *scale)
    return plate(center, p, thick)
