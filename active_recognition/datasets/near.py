# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""Near unknowns, generated: furniture-like objects of no ModelNet10 class, for outlier exposure.

The unknowns a robot in a home meets most are near the known classes: stools beside chairs,
open shelves and cabinets beside dressers and night stands, pianos and mantels beside desks.
Six kinds (stool, shelf, cabinet, appliance, piano, mantel), built from `parts` in styles that
combine two factors (a stool: its seat x its support). Only training reads them (train option
`near_outliers`), every style: thresholds are chosen and figures reported on real meshes
(real_unknowns.tsv), which no generator made. Shapes stand on z = 0 and face -y; deterministic in the seed.
"""
from __future__ import annotations

import numpy as np
import trimesh
from shapely.geometry import Polygon

from active_recognition.datasets.parts import Style, box, cushion, cylinder, disc, legs4, slab
from active_recognition.datasets.procedural import generated
from active_recognition.sensing.meshes import box_edge, normalise


def stool(rng, seat, support, st):  # seat: round, square, saddle | support: 3 legs, 4 legs and rungs, pedestal
    h, r = rng.uniform(0.42, 0.8), rng.uniform(0.15, 0.22)
    if seat == 0:
        parts = [disc((0, 0, h - 0.02), r, 0.04, st)]
    elif seat == 1:
        parts = [slab((0, 0, h - 0.02), (2 * r, 2 * r, 0.04), st)]
    else:
        parts = [cushion((0, 0, h - 0.03), (2.2 * r, 1.7 * r, 0.07), 0.6)]
    if support == 2:
        parts += [cylinder((0, 0, h / 2), 0.035, h - 0.04, st.sections),
                  cylinder((0, 0, 0.015), 0.8 * r, 0.03, st.sections),
                  cylinder((0, 0, 0.35 * h), 0.6 * r, 0.02, st.sections)]  # a foot ring
        return parts
    n = 3 if support == 0 else 4
    for k in range(n):
        a = 2 * np.pi * (k + 0.5) / n
        foot = 0.9 * r * np.array([np.cos(a), np.sin(a)])
        parts.append(box((*foot, (h - 0.04) / 2), (0.035, 0.035, h - 0.04)))
    if support == 1:  # rungs between the legs at a third of the height
        parts += [box((0, sy * 0.63 * r, 0.33 * h), (1.3 * r, 0.02, 0.02)) for sy in (-1, 1)]
        parts += [box((sx * 0.63 * r, 0, 0.33 * h), (0.02, 1.3 * r, 0.02)) for sx in (-1, 1)]
    return parts


def shelf(rng, build, back, st):  # build: bookcase, low and wide, cube grid | back: open, panel, cross brace
    w, d, h = {0: (rng.uniform(0.6, 1.0), rng.uniform(0.25, 0.4), rng.uniform(1.4, 2.0)),
               1: (rng.uniform(1.0, 1.8), rng.uniform(0.3, 0.45), rng.uniform(0.5, 0.9)),
               2: (rng.uniform(0.7, 1.5), rng.uniform(0.3, 0.4), rng.uniform(0.7, 1.5))}[build]
    t = rng.uniform(0.015, 0.03)
    n = max(2, int(round(h / rng.uniform(0.28, 0.38))))
    parts = [slab((sx * (w / 2 - t / 2), 0, h / 2), (t, d, h), st, axis=0) for sx in (-1, 1)]
    parts += [box((0, 0, t / 2 + k * (h - t) / n), (w - 2 * t, d, t)) for k in range(n + 1)]
    if build == 2:  # vertical dividers: a grid of cubes
        m = max(2, int(round(w / (h / n))))
        parts += [box((-w / 2 + k * w / m, 0, h / 2), (t, d, h - 2 * t)) for k in range(1, m)]
    if back == 1:
        parts.append(box((0, d / 2 - 0.005, h / 2), (w, 0.01, h)))
    elif back == 2:
        length = np.hypot(w, h)
        for sign in (-1, 1):
            s = box((0, 0, 0), (length, 0.01, 0.03))
            s.apply_transform(trimesh.transformations.rotation_matrix(sign * np.arctan2(h, w), (0, 1, 0)))
            s.apply_translation((0, d / 2 - 0.005, h / 2))
            parts.append(s)
    return parts


def fronts(w, h, z0, d, count, kind, rng):
    """`count` door or drawer fronts across a w-wide face at y = -d/2, from z0 to z0 + h: kind
    0 plain doors with bar handles, 1 framed (a raised frame around a recessed panel), 2 open."""
    parts, cw = [], w / count
    for k in range(count):
        x = -w / 2 + (k + 0.5) * cw
        if kind == 2:  # an open compartment: a back wall set in, the divider beside it
            parts.append(box((x, d / 4, z0 + h / 2), (cw - 0.03, 0.01, h - 0.03)))
            continue
        parts.append(box((x, -d / 2 - 0.01, z0 + h / 2), (cw - 0.008, 0.02, h - 0.008)))
        if kind == 1:
            parts += [box((x, -d / 2 - 0.025, z0 + h / 2 + sz * (h / 2 - 0.04)), (cw - 0.05, 0.012, 0.05))
                      for sz in (-1, 1)]
        hx = x + (cw / 2 - 0.06) * (1 if k % 2 else -1) if count > 1 else x + cw / 2 - 0.06
        parts.append(box((hx, -d / 2 - 0.035, z0 + h * rng.uniform(0.45, 0.6)), (0.015, 0.02, min(0.3, h / 3))))
    return parts


def cabinet(rng, kind, front, st):  # kind: wardrobe, kitchen counter, tv stand | front: doors, framed doors, open
    w, d, h = {0: (rng.uniform(0.8, 1.6), rng.uniform(0.5, 0.65), rng.uniform(1.7, 2.2)),
               1: (rng.uniform(1.2, 2.6), rng.uniform(0.55, 0.65), rng.uniform(0.85, 0.95)),
               2: (rng.uniform(1.2, 2.0), rng.uniform(0.35, 0.5), rng.uniform(0.4, 0.65))}[kind]
    kick = rng.uniform(0.06, 0.12) if kind != 2 else 0.0
    parts = [box((0, 0.03, kick / 2), (w - 0.04, d - 0.06, kick))] if kick else []
    parts.append(slab((0, 0, kick + (h - kick) / 2), (w, d, h - kick), st))
    if kind == 1:  # an overhanging worktop
        parts.append(box((0, -0.025, h + 0.02), (w + 0.04, d + 0.05, 0.04)))
    elif kind == 0:
        parts.append(slab((0, 0, h + 0.025), (w + 0.04, d + 0.03, 0.05), st))  # a cornice
    count = max(2, int(round(w / rng.uniform(0.4, 0.6))))
    parts += fronts(w, h - kick, kick, d, count, front, rng)
    return parts


def appliance(rng, kind, detail, st):  # kind: microwave, oven, fridge | detail: window, knobs, plain
    w, d, h = {0: (rng.uniform(0.45, 0.6), rng.uniform(0.35, 0.45), rng.uniform(0.26, 0.34)),
               1: (rng.uniform(0.55, 0.75), rng.uniform(0.55, 0.65), rng.uniform(0.85, 0.95)),
               2: (rng.uniform(0.6, 0.9), rng.uniform(0.6, 0.75), rng.uniform(1.5, 1.9))}[kind]
    parts = [slab((0, 0, h / 2), (w, d, h), st)]
    if kind == 0:  # a door left, a control panel right
        dw = 0.72 * w
        parts.append(box((-w / 2 + dw / 2, -d / 2 - 0.01, h / 2), (dw - 0.01, 0.02, h - 0.02)))
        if detail == 0:
            parts.append(box((-w / 2 + dw / 2, -d / 2 - 0.02, h / 2), (0.7 * dw, 0.005, 0.6 * h)))
        parts.append(box((-w / 2 + dw - 0.03, -d / 2 - 0.035, h / 2), (0.02, 0.02, 0.7 * h)))
    elif kind == 1:  # an oven door under a hob
        parts.append(box((0, -d / 2 - 0.01, 0.42 * h), (w - 0.02, 0.02, 0.65 * h)))
        parts.append(box((0, -d / 2 - 0.04, 0.74 * h), (0.8 * w, 0.02, 0.02)))
        if detail == 0:
            parts.append(box((0, -d / 2 - 0.02, 0.42 * h), (0.7 * w, 0.005, 0.4 * h)))
        parts += [cylinder((sx * w / 4, sy * d / 4, h + 0.005), 0.07, 0.01, st.sections)
                  for sx in (-1, 1) for sy in (-1, 1)]
        if detail == 1:
            parts += [cylinder((x, -d / 2 - 0.02, 0.88 * h), 0.02, 0.03, st.sections, axis=1)
                      for x in np.linspace(-0.35 * w, 0.35 * w, 5)]
    else:  # a fridge: a freezer door over the main one
        split = rng.uniform(0.3, 0.4) * h
        parts += [box((0, -d / 2 - 0.015, h - split / 2), (w - 0.01, 0.03, split - 0.01)),
                  box((0, -d / 2 - 0.015, (h - split) / 2), (w - 0.01, 0.03, h - split - 0.01))]
        x = w / 2 - 0.06
        parts += [box((x, -d / 2 - 0.05, h - split / 2), (0.025, 0.03, 0.25 * split)),
                  box((x, -d / 2 - 0.05, 0.7 * (h - split)), (0.025, 0.03, 0.25 * (h - split)))]
        if detail == 1:
            parts.append(box((-w / 4, -d / 2 - 0.035, h - split / 2), (0.2, 0.01, 0.28)))  # a dispenser
    return parts


def piano(rng, kind, extra, st):  # kind: upright, console, grand | extra: bench, music stand, none
    if kind == 2:
        w, L = rng.uniform(1.4, 1.6), rng.uniform(1.5, 2.2)
        outline = Polygon(
            [(-w / 2, 0), (w / 2, 0), (w / 2, 0.35 * L), (0.1 * w, 0.75 * L), (-0.2 * w, L), (-w / 2, L)])
        body = trimesh.creation.extrude_polygon(outline, 0.3)
        body.apply_translation((0, -L / 2, 0.62))
        parts = [body, box((0, -L / 2 - 0.12, 0.72), (w, 0.25, 0.08))]
        feet = ((-0.42 * w, 0.1), (0.42 * w, 0.1), (-0.3 * w, 0.9 * L))
        parts += [box((x, y - L / 2, 0.31), (0.07, 0.07, 0.62)) for x, y in feet]
        top, width = 1.0, w
    else:
        width, depth = rng.uniform(1.4, 1.55), rng.uniform(0.5, 0.65)
        top = rng.uniform(1.15, 1.35) if kind == 0 else rng.uniform(0.95, 1.05)
        parts = [slab((0, 0.1, top / 2), (width, depth - 0.2, top), st),
                 box((0, -depth / 2 + 0.1, 0.74), (width, 0.25, 0.08)),  # the keyboard
                 box((0, -depth / 2 + 0.2, 0.76 + 0.12), (width - 0.1, 0.05, 0.24))]
        parts += [box((sx * (width / 2 - 0.04), -depth / 2 + 0.04, 0.35), (0.06, 0.06, 0.7)) for sx in (-1, 1)]
    if extra == 0:  # a bench before the keys
        parts += [box((0, -1.0, 0.48), (0.8, 0.35, 0.06))] + [
            b.apply_translation((0, -1.0, 0)) for b in legs4(0.8, 0.35, 0.45, 0.04, 0.04, st)]
    elif extra == 1:
        parts.append(box((0, -0.2 if kind == 2 else 0.0, top + 0.15), (0.6 * width, 0.03, 0.3)))
    return parts


def mantel(rng, frame, shelf_kind, st):  # frame: pillars, plain slab, arched | shelf: thin, deep, with mirror
    w, h = rng.uniform(1.1, 1.8), rng.uniform(1.0, 1.3)
    ow, oh = rng.uniform(0.45, 0.6) * w, rng.uniform(0.55, 0.7) * h
    d = rng.uniform(0.15, 0.3)
    side = (w - ow) / 2
    parts = [box((sx * (ow / 2 + side / 2), 0, h / 2), (side, d, h)) for sx in (-1, 1)]
    parts.append(box((0, 0, oh + (h - oh) / 2), (ow, d, h - oh)))
    parts.append(box((0, d / 2 + 0.05, oh / 2), (ow, 0.1, oh)))  # the firebox's back
    parts.append(box((0, -0.15, 0.02), (w + 0.2, 0.45, 0.04)))  # a hearth
    if frame == 0:
        parts += [cylinder((sx * (ow / 2 + side / 2), -d / 2 - 0.04, h / 2), 0.05, h, st.sections)
                  for sx in (-1, 1)]
    elif frame == 2:
        arch = trimesh.creation.cylinder(radius=ow / 2, height=d + 0.02, sections=max(8, st.sections))
        arch.apply_transform(trimesh.transformations.rotation_matrix(np.pi / 2, (1, 0, 0)))
        arch.apply_translation((0, 0, oh))
        parts.append(arch)
    sd = d + (0.06 if shelf_kind != 1 else 0.2)
    parts.append(slab((0, -(sd - d) / 2, h + 0.03), (w + 0.15, sd, 0.06), st))
    if shelf_kind == 2:
        parts.append(box((0, d / 2 - 0.02, h + 0.06 + 0.4), (0.8 * w, 0.03, 0.8)))
    return parts


KINDS = ("stool", "shelf", "cabinet", "appliance", "piano", "mantel")
GENERATORS = {name: globals()[name] for name in KINDS}
FACTORS = {name: (3, 3) for name in KINDS}  # options per factor (a, b) of each kind
VERSION = 1  # bump when a builder changes, so caches are rebuilt
PER_CLASS = {"train": 100}  # training reads them; choices and figures are the real unknowns'


def make_near(label: int, seed: int):
    """One object of kind `label` in any of its styles, from `seed`: (vertices in [-0.5, 0.5]^3,
    faces, its size: the longest edge of its box in metres, as built)."""
    rng = np.random.default_rng(seed)
    name = KINDS[label]
    na, nb = FACTORS[name]
    a, b = int(rng.integers(na)), int(rng.integers(nb))
    mesh = trimesh.util.concatenate(GENERATORS[name](rng, a, b, Style.draw(rng)))
    return (normalise(mesh.vertices).astype(np.float32), np.asarray(mesh.faces, dtype=np.int32),
            box_edge(mesh.vertices))


def near_unknowns(split="train", cache_dir=None, seed=0, per_class=None):
    """The near unknowns as a ShapeDataset (procedural.generated), sizes in metres: a `train`
    split only, every style of every kind."""
    return generated("near_unknowns", KINDS, make_near, VERSION, split, cache_dir, seed, per_class,
                     PER_CLASS, metres=True)
