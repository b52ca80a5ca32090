# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""An embedded benchmark where the choice of view decides: six pairs of look-alike furniture.

Every class is a piece of furniture with a deep niche in one face. The two classes of a pair
share everything (base, proportions, niche) except what sits at the back of the niche: a
`drawer` (a block standing out of the back wall) or a `hollow` (the back wall opens into a
deeper hole). The niche's walls hide its back from every view but those that look into it, so
the pair is told apart only from a cone of about 45 degrees around that face's normal. The
pairs' niches lie on the five faces a robot can see an object on a floor from (front, back, top,
right and left sides; two pairs open at the front), so no fixed sequence of views serves every
pair: a planner has to look, see which piece of furniture it is, and then go to that piece's
telling side. Shapes are upright (+Z) and face -Y, like ModelNet's; proportions,
niche size and the detail's size and position vary within a class; deterministic in the seed.
"""
from __future__ import annotations

import numpy as np
import trimesh

from active_recognition.datasets.parts import Style, box, cushion, cylinder, legs4
from active_recognition.datasets.parts import slab as panel
from active_recognition.sensing.meshes import normalise

# (base, axis, sign): the face whose niche tells the pair apart
PAIRS = (("nightstand", 1, -1),   # front
         ("bookcase", 1, 1),      # back
         ("counter", 2, 1),       # top
         ("ottoman", 1, -1),      # front (not the bottom: a robot cannot look from below a floor)
         ("sideboard", 0, 1),     # right side (+X)
         ("lectern", 0, -1))      # left side (-X)
DETAILS = ("drawer", "hollow")
CLASSES = tuple(f"{base}_{detail}" for base, _, _ in PAIRS for detail in DETAILS)
SIDES = {(1, -1): "front", (1, 1): "back", (2, 1): "top", (2, -1): "bottom", (0, 1): "right",
         (0, -1): "left"}


def slab(center, size, axis, lo, hi):
    """A box spanning [lo, hi] along `axis` (absolute), center/size elsewhere."""
    c, s = np.array(center, float), np.array(size, float)
    c[axis], s[axis] = (lo + hi) / 2, hi - lo
    return box(c, s)


def niche_body(rng, center, size, axis, sign, detail):
    """A box of `size` at `center` with a niche opening on face (axis, sign); its back holds
    the pair's detail. Returns the parts."""
    center, size = np.asarray(center, float), np.asarray(size, float)
    b, c = [a for a in range(3) if a != axis]
    face = center[axis] + sign * size[axis] / 2
    back = center[axis] - sign * size[axis] / 2
    depth = rng.uniform(0.6, 0.7) * size[axis]             # niche depth
    wall = rng.uniform(0.06, 0.09) * min(size[b], size[c])   # frame around the opening
    inner = size.copy()
    inner[b], inner[c] = size[b] - 2 * wall, size[c] - 2 * wall
    floor = face - sign * depth                               # the niche's back wall
    parts = [slab(center, size, axis, min(back, floor), max(back, floor))]
    lo, hi = sorted((face, floor))
    for k, s in ((b, 1), (b, -1), (c, 1), (c, -1)):         # the frame walls
        cw, sw = center.copy(), size.copy()
        cw[k] = center[k] + s * (size[k] / 2 - wall / 2)
        sw[k] = wall
        if k == c:  # the c walls run between the b walls
            sw[b] = size[b] - 2 * wall
        parts.append(slab(cw, sw, axis, lo, hi))
    # the detail, off centre by up to 10 % of the opening
    dc = center.copy()
    dc[b] += rng.uniform(-0.1, 0.1) * inner[b]
    dc[c] += rng.uniform(-0.1, 0.1) * inner[c]
    ds = inner.copy()
    ds[b] *= rng.uniform(0.55, 0.75)
    ds[c] *= rng.uniform(0.55, 0.75)
    if detail == "drawer":  # a block out of the back wall, 40-55 % of the niche deep
        out = floor + sign * rng.uniform(0.4, 0.55) * depth
        parts.append(slab(dc, ds, axis, min(floor, out), max(floor, out)))
    else:  # hollow: cut a hole into the back block by rebuilding it as a frame around the hole
        hole = rng.uniform(0.7, 0.9) * abs(floor - back)
        bottom = floor - sign * hole
        parts[0] = slab(center, size, axis, min(back, bottom), max(back, bottom))
        lo2, hi2 = sorted((floor, bottom))
        b_lo, b_hi = dc[b] - ds[b] / 2, dc[b] + ds[b] / 2
        c_lo, c_hi = dc[c] - ds[c] / 2, dc[c] + ds[c] / 2
        ext_b = (center[b] - size[b] / 2, center[b] + size[b] / 2)
        ext_c = (center[c] - size[c] / 2, center[c] + size[c] / 2)
        for bl, bh in ((ext_b[0], b_lo), (b_hi, ext_b[1])):   # the slabs beside the hole
            pc, ps = center.copy(), size.copy()
            pc[b], ps[b] = (bl + bh) / 2, bh - bl
            parts.append(slab(pc, ps, axis, lo2, hi2))
        for cl, ch in ((ext_c[0], c_lo), (c_hi, ext_c[1])):   # above and below it
            pc, ps = center.copy(), size.copy()
            pc[b], ps[b] = dc[b], ds[b]
            pc[c], ps[c] = (cl + ch) / 2, ch - cl
            parts.append(slab(pc, ps, axis, lo2, hi2))
    return parts


def dressing(rng, held_out=False):
    """The furniture style of a piece (edges, legs, resolution), drawn before its proportions so
    that both twins of a pair get the same one. Training dressing: sharp or bevelled edges and
    square, round or tapered legs; held out (the cross split): rounded edges, turned or splayed
    legs."""
    st = Style.draw(rng)
    st.edge = "round" if held_out else ("sharp", "bevel")[rng.integers(2)]
    kinds = ("turned", "splayed") if held_out else ("square", "round", "tapered")
    st.leg = kinds[rng.integers(len(kinds))]
    return st


def four_legs(rng, w, d, h, st, inset=0.04):
    return legs4(w, d, h, inset, rng.uniform(0.04, 0.07), st)


def top(w, d, z, st):
    """A top board overhanging the carcass, with the style's edges."""
    return [panel((0, 0, z + 0.015), (w + 0.04, d + 0.04, 0.03), st)]


def nightstand(rng, detail, st):  # a cube-ish cabinet on four legs, niche in front
    w, d, h = rng.uniform(0.5, 0.6), rng.uniform(0.5, 0.6), rng.uniform(0.5, 0.6)
    leg = rng.uniform(0.1, 0.16)
    return (four_legs(rng, w, d, leg, st) + top(w, d, leg + h, st)
            + niche_body(rng, (0, 0, leg + h / 2), (w, d, h), 1, -1, detail))


def bookcase(rng, detail, st):  # tall and narrow on a plinth, niche at the back
    w, d, h = rng.uniform(0.65, 0.75), rng.uniform(0.6, 0.7), rng.uniform(0.8, 0.9)
    plinth = rng.uniform(0.05, 0.1)
    return ([panel((0, 0, plinth / 2), (w * 0.9, d * 0.9, plinth), st)] + top(w, d, plinth + h, st)
            + niche_body(rng, (0, 0, plinth + h / 2), (w, d, h), 1, 1, detail))


def counter(rng, detail, st):  # a wide block with an overhanging top band, niche in the top
    w, d, h = rng.uniform(0.8, 0.95), rng.uniform(0.7, 0.8), rng.uniform(0.75, 0.85)
    kick = rng.uniform(0.06, 0.1)
    return ([panel((0, 0.03, kick / 2), (w * 0.95, d * 0.85, kick), st)]
            + niche_body(rng, (0, 0, kick + h / 2), (w, d, h), 2, 1, detail))


def ottoman(rng, detail, st):  # a low cushion-topped block on the floor, niche in front
    w, d, h = rng.uniform(0.7, 0.8), rng.uniform(0.7, 0.8), rng.uniform(0.55, 0.65)
    pad = cushion((0, 0, h + 0.04), (w * 0.9, d * 0.9, 0.1), rng.uniform(0.3, 0.9),
                  subdivisions=1 + st.quad_segs // 3)
    return [pad] + niche_body(rng, (0, 0, h / 2), (w, d, h), 1, -1, detail)


def sideboard(rng, detail, st):  # low on tall legs, niche at its right end
    w, d, h = rng.uniform(0.7, 0.8), rng.uniform(0.6, 0.7), rng.uniform(0.55, 0.65)
    leg = rng.uniform(0.2, 0.25)
    return (four_legs(rng, w, d, leg, st, inset=0.06) + top(w, d, leg + h, st)
            + niche_body(rng, (0, 0, leg + h / 2), (w, d, h), 0, 1, detail))


def lectern(rng, detail, st):  # a box on a central column and a foot plate, niche at its left side
    w, d, h = rng.uniform(0.65, 0.75), rng.uniform(0.6, 0.7), rng.uniform(0.45, 0.55)
    col = rng.uniform(0.3, 0.4)
    return ([panel((0, 0, 0.02), (w * 0.8, d * 0.8, 0.04), st),
             cylinder((0, 0, col / 2), rng.uniform(0.07, 0.1), col, sections=st.sections)]
            + top(w, d, col + h, st)
            + niche_body(rng, (0, 0, col + h / 2), (w, d, h), 0, -1, detail))


BASES = {"nightstand": nightstand, "bookcase": bookcase, "counter": counter, "ottoman": ottoman,
         "sideboard": sideboard, "lectern": lectern}


def face_view(axis, sign, tilt=0.3):
    """(theta, phi) looking at face (axis, sign) from `tilt` radians off its normal."""
    normal, other = np.zeros(3), np.zeros(3)
    normal[axis], other[(axis + 1) % 3] = sign, 1.0
    d = np.cos(tilt) * normal + np.sin(tilt) * other
    return float(np.arccos(np.clip(d[2], -1, 1))), float(np.arctan2(d[1], d[0]))


def pair_sheet(seed=0):
    """Contact-sheet rows, one per pair built from one seed: both twins seen into their niche
    (tells them apart), then both from the opposite side (does not).
    Returns (images (6, 4, 64, 64), row labels, column titles)."""
    from active_recognition.sensing.depth_layer import DepthCamera
    rows, labels = [], []
    for pair, (base, axis, sign) in enumerate(PAIRS):
        views = np.array([face_view(axis, sign), face_view(axis, -sign)])
        a, b = (DepthCamera(*make_shape(2 * pair + k, seed + pair)).render(views) for k in (0, 1))
        rows.append([a[0], b[0], a[1], b[1]])
        labels.append(f"{base} ({SIDES[axis, sign]})")
    titles = [f"{DETAILS[0]}, niche", f"{DETAILS[1]}, niche", f"{DETAILS[0]}, opposite",
              f"{DETAILS[1]}, opposite"]
    return np.array(rows), labels, titles


def make_shape(label: int, seed: int, held_out=False):
    """Build one shape of class `label` from `seed`: (vertices (V, 3) in [-0.5, 0.5]^3, faces).

    The twins of a pair draw the same style and proportions from the same seed, so a pair
    differs only by its detail."""
    base, _, _ = PAIRS[label // 2]
    rng = np.random.default_rng(seed)
    st = dressing(rng, held_out)
    mesh = trimesh.util.concatenate(BASES[base](rng, DETAILS[label % 2], st))
    return normalise(mesh.vertices).astype(np.float32), np.asarray(mesh.faces, dtype=np.int32)


VERSION = 6  # bump when a generator changes, so caches are rebuilt


def twins(split="train", cache_dir=None, seed=0, per_class=None):
    """The twins benchmark as a ShapeDataset: 200 train / 50 test objects per class; `cross`
    holds pieces in the held-out dressing."""
    from active_recognition.datasets.procedural import generated
    held_out = split == "cross"
    return generated("twins", CLASSES, lambda label, s: make_shape(label, s, held_out), VERSION,
                     split, cache_dir, seed, per_class)
