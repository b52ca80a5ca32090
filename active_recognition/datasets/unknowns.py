# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""Objects of no ModelNet10 class, generated: what an open-set recognizer should call `unknown`.

Nine kinds (cup, vase, bottle, lamp, plant, airplane, guitar, stairs, bench), each built from
`parts` in styles that combine two factors (a lamp: its base x its shade), in the manner of
`furniture`. The styles of each kind are dealt, by a seeded permutation, to three disjoint
groups: `train` (for outlier exposure in a retrain), `val` (where an operating point is chosen)
and `test` (read only for the final figures), so the test objects are of styles that nothing was
chosen or trained on. Shapes stand on z = 0 and face -y; deterministic in the seed.
"""
from __future__ import annotations

import numpy as np
import trimesh
from shapely import affinity
from shapely.geometry import Point, Polygon
from shapely.ops import unary_union

from active_recognition.datasets.parts import Style, box, cushion, cylinder, disc, extrude, legs4, place, slab, turned
from active_recognition.datasets.procedural import generated
from active_recognition.sensing.meshes import box_edge, normalise


def revolved(z0, radii, height, st):
    """A closed revolved profile along z standing on z0 (radii from bottom to top)."""
    return turned((0, 0, z0 + height / 2), radii, height, st.sections)


def cup(rng, body, handle, st):  # body: straight, tapered, bulged | handle: none, ring, square
    r, h = rng.uniform(0.035, 0.05), rng.uniform(0.08, 0.12)
    radii = {0: [r] * 4, 1: [0.7 * r, 0.8 * r, 0.9 * r, r], 2: [0.8 * r, 1.1 * r, 1.05 * r, 0.85 * r]}[body]
    parts = [revolved(0, radii, h, st), disc((0, 0, h + 0.002), 0.85 * r, 0.004, st)]
    if handle == 1:
        ring = trimesh.creation.torus(0.3 * h, 0.006, major_sections=st.sections, minor_sections=8)
        parts.append(place(ring, (r + 0.2 * h, 0, h / 2), axis=1))
    elif handle == 2:
        x = r + 0.025
        parts += [box((x, 0, h / 2), (0.01, 0.01, 0.6 * h)),
                  box((r + 0.01, 0, 0.8 * h), (0.03, 0.01, 0.01)), box((r + 0.01, 0, 0.2 * h), (0.03, 0.01, 0.01))]
    return parts


def vase(rng, profile, foot, st):  # profile: amphora, column, bulb | foot: none, ring, square plinth
    r, h = rng.uniform(0.06, 0.12), rng.uniform(0.2, 0.45)
    radii = {0: [0.5, 0.9, 1.0, 0.7, 0.35, 0.45], 1: [0.8, 0.8, 0.82, 0.82, 0.85, 0.9],
             2: [0.6, 1.0, 0.95, 0.5, 0.25, 0.3]}[profile]
    z0 = (0.0, 0.02, 0.04)[foot]
    parts = [revolved(z0, [r * k * rng.uniform(0.9, 1.1) for k in radii], h, st)]
    if foot == 1:
        parts.append(cylinder((0, 0, 0.01), 0.6 * r, 0.02, st.sections))
    elif foot == 2:
        parts.append(slab((0, 0, 0.02), (1.6 * r, 1.6 * r, 0.04), st))
    return parts


def bottle(rng, body, neck, st):  # body: round, square, flask | neck: short, long, capped
    r, h = rng.uniform(0.03, 0.05), rng.uniform(0.15, 0.3)
    nl = (0.15, 0.35, 0.2)[neck] * h
    if body == 0:
        parts = [revolved(0, [r, r, r, 0.9 * r], h, st)]
    elif body == 1:
        parts = [slab((0, 0, h / 2), (2 * r, 2 * r, h), st)]
    else:  # a flat flask
        parts = [slab((0, 0, h / 2), (2.4 * r, 0.9 * r, h), Style("round", quad_segs=st.quad_segs), axis=1)]
    parts.append(revolved(h, [0.8 * r, 0.4 * r, 0.3 * r, 0.3 * r], nl, st))
    if neck == 2:
        parts.append(cylinder((0, 0, h + nl + 0.01), 0.38 * r, 0.02, st.sections))
    return parts


def lamp(rng, base, shade, st):  # base: disc, square, tripod | shade: cone, drum, globe
    h, s = rng.uniform(0.3, 0.7), rng.uniform(0.1, 0.2)
    if base == 2:
        parts = legs4(0.25, 0.25, h * 0.3, 0.0, 0.015, st, kind="splayed")[:3]
        parts.append(cylinder((0, 0, h * 0.3 + 0.01), 0.03, 0.02, st.sections))
    elif base == 1:
        parts = [slab((0, 0, 0.015), (0.2, 0.2, 0.03), st)]
    else:
        parts = [disc((0, 0, 0.01), rng.uniform(0.07, 0.12), 0.02, st)]
    z = h * 0.3 if base == 2 else 0.02
    parts.append(cylinder((0, 0, (z + h) / 2), 0.008, h - z, st.sections))
    if shade == 0:
        parts.append(revolved(h - 0.3 * s, [s, 0.75 * s, 0.5 * s], 0.9 * s, st))
    elif shade == 1:
        parts.append(cylinder((0, 0, h + 0.2 * s), 0.7 * s, 0.8 * s, st.sections))
    else:
        parts.append(trimesh.creation.icosphere(2, radius=0.5 * s).apply_translation((0, 0, h + 0.3 * s)))
    return parts


def plant(rng, pot, leaves, st):  # pot: drum, tapered, square | leaves: bush, blades, tree
    r, ph = rng.uniform(0.08, 0.16), rng.uniform(0.12, 0.25)
    if pot == 2:
        parts = [slab((0, 0, ph / 2), (2 * r, 2 * r, ph), st)]
    else:
        parts = [revolved(0, [r * (0.7 if pot else 1.0), r], ph, st)]
    if leaves == 0:
        parts += [cushion((*(rng.uniform(-0.6, 0.6, 2) * r), ph + rng.uniform(0.3, 1.0) * r),
                          [rng.uniform(0.8, 1.3) * r] * 3, 0.0) for _ in range(int(rng.integers(3, 7)))]
    elif leaves == 1:  # upright blades leaning outward
        for k in range(int(rng.integers(5, 10))):
            a, ln = 2 * np.pi * k / 7 + rng.uniform(-0.3, 0.3), rng.uniform(2, 4) * r
            blade = box((0, 0, ln / 2), (0.3 * r, 0.03 * r, ln))
            lean = trimesh.transformations.rotation_matrix(rng.uniform(0.1, 0.5), (-np.sin(a), np.cos(a), 0))
            blade.apply_transform(lean)
            parts.append(blade.apply_translation((0, 0, ph)))
    else:  # a trunk and a cone of foliage
        th = rng.uniform(1.0, 2.0) * r
        parts += [cylinder((0, 0, ph + th / 2), 0.08 * r, th, st.sections),
                  revolved(ph + th, [1.5 * r, 1.0 * r, 0.4 * r, 0.05 * r], rng.uniform(2, 4) * r, st)]
    return parts


def wing(span, chord, sweep, z, thick):
    """A pair of wings (a trapezoid each side of x = 0 at height z), the fuselage along x."""
    half = Polygon([(0, 0), (-sweep, span / 2), (-sweep - 0.4 * chord, span / 2), (-chord, 0)])
    both = unary_union([half, affinity.scale(half, 1, -1, origin=(0, 0))])
    return extrude(both, thick, (0, 0, z))


def airplane(rng, wings, tail, st):  # wings: straight, swept, delta | tail: plain, T-tail, twin fins
    L, r = rng.uniform(3, 6), rng.uniform(0.15, 0.3)
    span, z = L * rng.uniform(0.8, 1.2), r
    body = turned((0, 0, 0), [0.2 * r, 0.9 * r, r, r, r, 0.8 * r, 0.3 * r], L, st.sections)
    parts = [place(body, (0, 0, z), axis=0)]
    sweep, chord = {0: (0.05 * L, 0.15 * L), 1: (0.3 * L, 0.15 * L), 2: (0.45 * L, 0.5 * L)}[wings]
    w = wing(span, chord, sweep, z, 0.05 * r)
    parts.append(w.apply_translation((0.2 * L if wings < 2 else 0.3 * L, 0, 0)))
    fin = extrude(Polygon([(0, 0), (-0.15 * L, 0), (-0.2 * L, 0.2 * L), (-0.12 * L, 0.2 * L)]), 0.04 * r,
                  (0, 0, 0), axis=1)
    tx = -0.32 * L
    if tail == 2:  # twin fins on a tailplane
        parts.append(wing(0.35 * span, 0.1 * L, 0.05 * L, z, 0.04 * r).apply_translation((tx + 0.1 * L, 0, 0)))
        parts += [fin.copy().apply_translation((tx + 0.15 * L, sy * 0.15 * span, z)) for sy in (-1, 1)]
    else:
        zt = z + (0.2 * L if tail == 1 else 0)
        parts += [fin.apply_translation((tx + 0.15 * L, 0, z)),
                  wing(0.35 * span, 0.1 * L, 0.05 * L, zt, 0.04 * r).apply_translation((tx + 0.1 * L, 0, 0))]
    if rng.random() < 0.5:  # engines under the wings
        parts += [cylinder((0.1 * L, sy * span / 4, 0.3 * r), 0.35 * r, 0.15 * L, st.sections, axis=0)
                  for sy in (-1, 1)]
    return parts


def guitar(rng, body, head, st):  # body: two lobes, round, V | head: straight, angled, wide
    b, t = rng.uniform(0.3, 0.4), rng.uniform(0.06, 0.11)
    if body == 0:
        outline = unary_union([Point(0, 0.28 * b).buffer(0.28 * b), Point(0, 0.7 * b).buffer(0.22 * b),
                               Polygon([(-0.2 * b, 0.3 * b), (0.2 * b, 0.3 * b), (0.15 * b, 0.7 * b),
                                        (-0.15 * b, 0.7 * b)])])
    elif body == 1:
        outline = affinity.scale(Point(0, 0.45 * b).buffer(0.45 * b), 0.8, 1)
    else:
        outline = Polygon([(0, 0), (0.45 * b, 0.1 * b), (0.15 * b, 0.9 * b), (0, 0.7 * b), (-0.15 * b, 0.9 * b),
                           (-0.45 * b, 0.1 * b)])
    parts = [extrude(outline, t, (0, 0, 0), axis=1)]  # upright, the face toward -y
    neck = rng.uniform(1.0, 1.3) * b
    parts.append(box((0, 0, 0.85 * b + neck / 2), (0.06 * b, 0.4 * t, neck)))
    hl, top = 0.3 * b, 0.85 * b + neck
    hw = (0.1, 0.1, 0.2)[head] * b
    h = box((0, 0, hl / 2), (hw, 0.3 * t, hl))
    if head == 1:
        h.apply_transform(trimesh.transformations.rotation_matrix(0.25, (1, 0, 0)))
    parts.append(h.apply_translation((0, 0, top)))
    return parts


def stairs(rng, run, build, st):  # run: straight, with a landing, wide and short | build: solid, treads, railed
    n, rise, tread = int(rng.integers(4, 12)), rng.uniform(0.15, 0.2), rng.uniform(0.22, 0.32)
    w = (rng.uniform(0.8, 1.2), rng.uniform(0.8, 1.2), rng.uniform(1.5, 2.5))[run]
    parts, x, z = [], 0.0, 0.0
    for k in range(n):
        if run == 1 and k == n // 2:  # a landing
            parts.append(box((x + tread, 0, z / 2 + 0.001), (2 * tread, w, z)))
            x += 2 * tread
        z += rise
        if build == 1:  # open treads on two stringers
            parts.append(box((x + tread / 2, 0, z - 0.02), (tread, w, 0.04)))
        else:
            parts.append(box((x + tread / 2, 0, z / 2), (tread, w, z)))
        x += tread
    if build != 0:
        length = np.hypot(x, z)
        for sy in (-1, 1):
            s = box((0, 0, 0), (length, 0.04, 0.15))
            s.apply_transform(trimesh.transformations.rotation_matrix(-np.arctan2(z, x), (0, 1, 0)))
            s.apply_translation((x / 2, sy * (w / 2 + 0.02), z / 2 + (0.9 if build == 2 else 0)))
            parts.append(s)
    if build == 2:
        parts += [box((x * f, sy * (w / 2 + 0.02), z * f + 0.45), (0.04, 0.04, 0.9))
                  for f in (0.1, 0.5, 0.9) for sy in (-1, 1)]
    return parts


def bench(rng, seat, support, st):  # seat: slab, slats, padded | support: legs, panels, back and arms
    L, d, h = rng.uniform(1.0, 2.0), rng.uniform(0.3, 0.5), rng.uniform(0.4, 0.48)
    if seat == 1:
        n = int(rng.integers(3, 6))
        parts = [box((0, -d / 2 + d * (k + 0.5) / n, h - 0.02), (L, d / n * 0.7, 0.04)) for k in range(n)]
    elif seat == 2:
        parts = [cushion((0, 0, h - 0.04), (L, d, 0.1), 0.8)]
    else:
        parts = [slab((0, 0, h - 0.03), (L, d, 0.06), st)]
    if support == 1:
        parts += [slab((sx * (L / 2 - 0.1), 0, (h - 0.06) / 2), (0.05, d, h - 0.06), st, axis=0) for sx in (-1, 1)]
    else:
        parts += legs4(L, d, h - 0.06, 0.06, 0.05, st)
    if support == 2:
        bh = rng.uniform(0.3, 0.45)
        parts.append(slab((0, d / 2 - 0.02, h + bh / 2), (L, 0.04, bh), st, axis=1))
        parts += [box((sx * (L / 2 - 0.03), 0, h + 0.2), (0.05, d, 0.04)) for sx in (-1, 1)]
    return parts


KINDS = ("cup", "vase", "bottle", "lamp", "plant", "airplane", "guitar", "stairs", "bench")
GENERATORS = {name: globals()[name] for name in KINDS}
FACTORS = {name: (3, 3) for name in KINDS}  # options per factor (a, b) of each kind
SPLITS = ("train", "val", "test")
STYLE_SEED = 0  # how the styles of each kind are dealt to the splits
VERSION = 2  # bump when a builder changes, so caches are rebuilt
PER_CLASS = {"train": 100, "val": 30, "test": 50}


def styles(name, split):
    """The (a, b) combinations of kind `name` in `split`: a seeded permutation of all of them,
    its first third `val`, its second `test`, the rest `train` (disjoint, each non-empty)."""
    from active_recognition.argument_checks import InputError

    if name not in GENERATORS:
        raise InputError(f"unknown-object kind must be one of {', '.join(KINDS)}, got {name!r}")
    if split not in SPLITS:
        raise InputError(f"split of unknowns must be one of {', '.join(SPLITS)}, got {split!r}")
    na, nb = FACTORS[name]
    combos = [(a, b) for a in range(na) for b in range(nb)]
    order = np.random.default_rng([STYLE_SEED, KINDS.index(name)]).permutation(len(combos))
    third = len(combos) // 3
    part = {"val": order[:third], "test": order[third:2 * third], "train": order[2 * third:]}[split]
    return [combos[i] for i in sorted(part)]


def make_unknown(label: int, seed: int, split: str):
    """One object of kind `label` in a style of `split`, from `seed`: (vertices in [-0.5, 0.5]^3,
    faces, its size: the longest edge of its box in metres, as built)."""
    rng = np.random.default_rng(seed)
    name = KINDS[label]
    options = styles(name, split)
    pick = options[int(rng.random() * len(options))]
    mesh = trimesh.util.concatenate(GENERATORS[name](rng, *pick, Style.draw(rng)))
    return (normalise(mesh.vertices).astype(np.float32), np.asarray(mesh.faces, dtype=np.int32),
            box_edge(mesh.vertices))


def unknowns(split="train", cache_dir=None, seed=0, per_class=None):
    """The unknown objects of a split as a ShapeDataset (procedural.generated): its own `val`,
    of styles apart from both `train` and `test`; each object's size is its size as built, so
    the size prior weighs it as a robot's detector would."""
    from active_recognition.argument_checks import InputError

    if split not in SPLITS:
        raise InputError(f"split of unknowns must be one of {', '.join(SPLITS)}, got {split!r}")
    return generated("unknowns", KINDS, lambda label, s: make_unknown(label, s, split), VERSION, split,
                     cache_dir, seed, per_class, PER_CLASS, metres=True)
