"""The procedural benchmark's ten classes, four styles each, built from `parts`.

A style is a structure (a trestle table, an office chair, a clawfoot tub, a curved monitor);
within a style the proportions come from real furniture's ranges (metres) and the edges, legs
and mesh resolution vary (`parts.Style`). Styles 0 and 1 of every class are the training styles,
2 and 3 are held out: the cross-style split tests on them (a proxy for real objects, whose
styles a generator never matches). The designed confusions stay: table/desk (a desk has drawers,
pedestals or panels below), night_stand/dresser (a cube vs a wide or tall chest), sofa/bed/
bathtub (long low pieces: a back, a headboard, a hollow), chair/toilet (a seat with a back or
a tank). Shapes stand on z = 0 and face -y; every function returns a list of meshes.
"""
from __future__ import annotations

import numpy as np
from shapely import affinity
from shapely.geometry import Point, Polygon
from shapely.geometry import box as outline

from .parts import (Style, box, cushion, cylinder, disc, extrude, leg, legs4, pedestal, plate,
                    ring, shell, slab, star_base, turned)

STYLES = 4
TRAIN_STYLES, HELD_OUT_STYLES = (0, 1), (2, 3)


def drawers(x, y, z0, w, h, cols, rows, rng, st):
    """Drawer fronts with handles on a cabinet face at y (facing -y), bottom z0."""
    parts, cw, rh = [], w / cols, h / rows
    knob = rng.random() < 0.5
    for c in range(cols):
        for r in range(rows):
            cx, cz = x - w / 2 + cw * (c + 0.5), z0 + rh * (r + 0.5)
            parts.append(slab((cx, y - 0.01, cz), (cw * 0.9, 0.02, rh * 0.84), st, axis=1))
            parts.append(cylinder((cx, y - 0.03, cz), 0.012, 0.03, st.sections, axis=1) if knob
                         else box((cx, y - 0.03, cz), (cw * 0.3, 0.02, 0.02)))
    return parts


def table(rng, s, st):
    w, d = rng.uniform(0.8, 1.8), rng.uniform(0.6, 1.0)
    h, t = rng.uniform(0.7, 0.78), rng.uniform(0.02, 0.05)
    leg_t = rng.uniform(0.04, 0.08)
    if s in (1, 3):  # round or oval top
        d = w * rng.uniform(0.6, 1.0)
        top = [disc((0, 0, h - t / 2), 0.5, t, st, scale=(w, d))]
    else:
        top = [slab((0, 0, h - t / 2), (w, d, t), st)]
    if s == 0:
        parts = legs4(w, d, h - t, rng.uniform(0.04, 0.1), leg_t, st)
        if rng.random() < 0.6:  # aprons
            parts += [box((0, sy * (d / 2 - 0.06), h - t - 0.05), (w - 0.14, 0.02, 0.1)) for sy in (-1, 1)]
    elif s == 1:
        parts = pedestal(h - t, rng.uniform(0.04, 0.08), rng.uniform(0.2, 0.3) * w, st)
    elif s == 2:  # trestle: two end frames on feet and a stretcher
        parts = []
        for sx in (-1, 1):
            x = sx * (w / 2 - rng.uniform(0.1, 0.2))
            parts += [slab((x, 0, (h - t) / 2), (0.06, 0.12, h - t), st, axis=0),
                      box((x, 0, 0.03), (0.08, d * 0.8, 0.06)), box((x, 0, h - t - 0.03), (0.08, d * 0.7, 0.05))]
        parts.append(box((0, 0, 0.25 * h), (w * 0.7, 0.05, 0.06)))
    else:  # round top on legs with a shelf below
        parts = legs4(w * 0.7, d * 0.7, h - t, 0.03, leg_t, st)
        parts.append(disc((0, 0, 0.2 * h), 0.5, 0.02, st, scale=(w * 0.72, d * 0.72)))
    return top + parts


def desk(rng, s, st):
    w, d = rng.uniform(1.0, 1.8), rng.uniform(0.55, 0.85)
    h, t = rng.uniform(0.72, 0.77), rng.uniform(0.025, 0.05)
    top = [slab((0, 0, h - t / 2), (w, d, t), st)]
    under = h - t
    pw = rng.uniform(0.3, 0.45)
    def ped(side):  # a drawer pedestal under one end
        x = side * (w / 2 - pw / 2)
        return [box((x, 0, under / 2), (pw, d * 0.95, under))] + drawers(
            x, -d * 0.475, 0.03, pw, under - 0.05, 1, int(rng.integers(2, 5)), rng, st)
    modesty = [box((0, d / 2 - 0.05, under * 0.6), (w * 0.9, 0.02, under * 0.5))]
    if s == 0:
        side = rng.choice([-1, 1])
        parts = ped(side) + [leg(st.leg, (-side * (w / 2 - 0.05), sy * (d / 2 - 0.05)), under,
                                 0.05, st, (-side, sy)) for sy in (-1, 1)]
        parts += modesty if rng.random() < 0.7 else []
    elif s == 1:
        parts = ped(-1) + ped(1) + modesty
    elif s == 2:  # panel ends, a modesty panel and a drawer row under the top
        parts = [slab((sx * (w / 2 - 0.02), 0, under / 2), (0.04, d, under), st, axis=0) for sx in (-1, 1)]
        parts += modesty + drawers(0, -d * 0.45, under - 0.12, w * 0.5, 0.11, 2, 1, rng, st)
        parts.append(box((0, 0, under - 0.06), (w * 0.5, d * 0.9, 0.12)))
    else:  # a writing desk on legs with a drawer row and a hutch at the back
        parts = legs4(w, d, under, 0.04, 0.05, st)
        parts += [box((0, 0, under - 0.06), (w * 0.9, d * 0.9, 0.1))]
        parts += drawers(0, -d * 0.45, under - 0.11, w * 0.8, 0.1, int(rng.integers(2, 4)), 1, rng, st)
        hh = rng.uniform(0.25, 0.45)
        parts += [box((sx * (w / 2 - 0.02), d / 2 - 0.12, h + hh / 2), (0.03, 0.22, hh)) for sx in (-1, 1)]
        parts += [box((0, d / 2 - 0.12, h + hh), (w, 0.24, 0.03)), box((0, d / 2 - 0.02, h + hh / 2), (w, 0.02, hh))]
    return top + parts


def cabinet(rng, st, w, d, h, z0, cols, rows):
    """A carcass from z0 to z0 + h with a drawer grid on the front and a top with an edge."""
    return ([box((0, 0, z0 + h / 2), (w, d, h)), slab((0, 0, z0 + h + 0.015), (w + 0.03, d + 0.02, 0.03), st)]
            + drawers(0, -d / 2, z0 + 0.02, w * 0.94, h - 0.04, cols, rows, rng, st))


def base(rng, st, w, d, tall):
    """What a cabinet stands on: a plinth, or legs of height `tall`."""
    if rng.random() < 0.5:
        return [box((0, 0, tall / 2), (w * 0.94, d * 0.9, tall))]
    return legs4(w, d, tall, 0.04, 0.045, st)


def night_stand(rng, s, st):
    w, d, h = rng.uniform(0.4, 0.6), rng.uniform(0.35, 0.5), rng.uniform(0.4, 0.55)
    if s == 0:
        z0 = rng.uniform(0.03, 0.1)
        return base(rng, st, w, d, z0) + cabinet(rng, st, w, d, h, z0, 1, int(rng.integers(1, 4)))
    if s == 1:  # one drawer on tall legs, an open shelf below
        z0 = rng.uniform(0.25, 0.35)
        return (legs4(w, d, z0, 0.03, 0.04, st) + cabinet(rng, st, w, d, h * 0.45, z0, 1, 1)
                + [box((0, 0, 0.1), (w * 0.92, d * 0.92, 0.02))])
    if s == 2:  # a drum: round body, one curved-front drawer, a round top
        r = w / 2
        return ([cylinder((0, 0, h / 2 + 0.05), r, h, st.sections), disc((0, 0, h + 0.065), r + 0.02, 0.03, st),
                 slab((0, -r - 0.005, h * 0.75), (w * 0.7, 0.02, h * 0.3), st, axis=1)]
                + pedestal(0.05, r * 0.7, r * 0.8, st))
    z0 = rng.uniform(0.15, 0.25)  # two drawers under an open cubby, on legs
    parts = legs4(w, d, z0, 0.03, 0.04, st, kind="tapered") + cabinet(rng, st, w, d, h * 0.6, z0, 1, 2)
    top = z0 + h * 0.6
    parts += [box((sx * (w / 2 - 0.01), 0, top + 0.1), (0.02, d, 0.2)) for sx in (-1, 1)]
    return parts + [slab((0, 0, top + 0.21), (w, d, 0.02), st), box((0, d / 2 - 0.01, top + 0.1), (w, 0.02, 0.2))]


def dresser(rng, s, st):
    w, d, h = rng.uniform(0.9, 1.6), rng.uniform(0.4, 0.55), rng.uniform(0.7, 1.0)
    z0 = rng.uniform(0.05, 0.15)
    if s == 0:
        return base(rng, st, w, d, z0) + cabinet(rng, st, w, d, h, z0, int(rng.integers(2, 4)),
                                                 int(rng.integers(3, 6)))
    if s == 1:  # on legs, a mirror on the back
        mh = rng.uniform(0.5, 0.8)
        parts = legs4(w, d, z0, 0.04, 0.05, st) + cabinet(rng, st, w, d, h, z0, 2, int(rng.integers(3, 5)))
        return parts + [slab((0, d / 2 - 0.05, z0 + h + mh / 2 + 0.03), (w * 0.7, 0.03, mh), st, axis=1)]
    if s == 2:  # a tall chest: narrow, many rows, two half drawers on top
        w, h = rng.uniform(0.7, 0.95), rng.uniform(1.1, 1.4)
        parts = base(rng, st, w, d, z0) + cabinet(rng, st, w, d, h * 0.85, z0, 1, int(rng.integers(4, 7)))
        return parts + cabinet(rng, st, w, d, h * 0.15, z0 + h * 0.85, 2, 1)
    # a sideboard: long and low, doors below a drawer row
    w, h = rng.uniform(1.4, 2.0), rng.uniform(0.7, 0.85)
    parts = legs4(w, d, z0, 0.05, 0.05, st) + cabinet(rng, st, w, d, h * 0.25, z0 + h * 0.75, 3, 1)
    parts.append(box((0, 0, z0 + h * 0.375), (w, d, h * 0.75)))
    doors = int(rng.integers(2, 5))
    for k in range(doors):
        x = -w / 2 + w * (k + 0.5) / doors
        parts += [slab((x, -d / 2 - 0.01, z0 + h * 0.375), (w / doors * 0.94, 0.02, h * 0.7), st, axis=1),
                  box((x + (0.35 if k % 2 else -0.35) * w / doors, -d / 2 - 0.03, z0 + h * 0.5), (0.02, 0.02, 0.12))]
    return parts


def sofa(rng, s, st):
    L, d = rng.uniform(1.5, 2.4), rng.uniform(0.8, 1.0)
    seat, back = rng.uniform(0.38, 0.46), rng.uniform(0.75, 0.95)
    z0 = 0.0 if s in (0, 2) else rng.uniform(0.1, 0.2)
    parts = [] if z0 == 0 else legs4(L * 0.95, d * 0.9, z0, 0.05, 0.04, st)
    arm_t = rng.uniform(0.12, 0.25)
    inner = L - 2 * arm_t
    parts.append(slab((0, 0, (z0 + seat - 0.12) / 2), (L, d, seat - 0.12 - z0), st))
    n = int(rng.integers(1, 4))
    for k in range(n):  # seat cushions
        parts.append(cushion((-inner / 2 + inner * (k + 0.5) / n, -0.06, seat - 0.06),
                             (inner / n * 0.97, d * 0.75, 0.14), rng.uniform(0.5, 0.9)))
    if s == 3:  # a curved back of pillows
        parts.append(shell((0, d / 2 - 0.08, (seat + back) / 2), L * 0.95, back - seat, 0.12, 0.08))
        parts += [cushion((-inner / 2 + inner * (k + 0.5) / n, d / 2 - 0.2, seat + 0.2),
                          (inner / n * 0.9, 0.18, 0.38), 0.4) for k in range(n)]
    else:
        parts.append(slab((0, d / 2 - 0.1, (seat + back) / 2), (L, 0.2, back - seat), st, axis=1))
    arm_h = seat + rng.uniform(0.12, 0.25)
    for sx in (-1, 1):
        x = sx * (L / 2 - arm_t / 2)
        if s == 1:  # rolled arms
            parts += [box((x, 0, (z0 + arm_h) / 2), (arm_t, d, arm_h - z0)),
                      cylinder((x, 0, arm_h), arm_t / 2 + 0.02, d, st.sections, axis=1)]
        elif s == 3:
            parts.append(slab((x, 0, (seat + arm_h) / 2), (arm_t * 0.6, d * 0.9, arm_h - seat + 0.1), st, axis=0))
        else:
            parts.append(slab((x, 0, arm_h / 2), (arm_t, d, arm_h), st, axis=2))
    if s == 2:  # a chaise on one end: an L
        side = rng.choice([-1, 1])
        cl = rng.uniform(0.6, 0.9)
        cw = rng.uniform(0.6, 0.8)
        x = side * (L / 2 - cw / 2)
        parts += [box((x, -d / 2 - cl / 2, (seat - 0.12) / 2), (cw, cl, seat - 0.12)),
                  cushion((x, -d / 2 - cl / 2 + 0.05, seat - 0.06), (cw * 0.95, cl * 0.9, 0.14), 0.7)]
    return parts


def bed(rng, s, st):
    L, w = rng.uniform(1.95, 2.2), rng.uniform(0.9, 1.9)
    frame, mat = rng.uniform(0.2, 0.35), rng.uniform(0.18, 0.3)
    parts = []
    if s in (0, 3):  # a platform, or an upholstered base
        parts.append(slab((0, 0, frame / 2), (L, w, frame), st))
    else:  # rails on legs
        parts += legs4(L, w, frame, 0.04, 0.07, st)
        parts += [box((0, sy * (w / 2 - 0.02), frame - 0.08), (L, 0.04, 0.16)) for sy in (-1, 1)]
    parts.append(cushion((0, 0, frame + mat / 2), (L * 0.98, w * 0.97, mat), 0.85))
    hx = -L / 2 - 0.03
    head = frame + mat + rng.uniform(0.25, 0.7)
    if s == 0:
        parts.append(slab((hx, 0, head / 2), (0.06, w + 0.04, head), st, axis=0))
    elif s == 1:  # four posts and a canopy frame
        top = rng.uniform(1.7, 2.1)
        for sx in (-1, 1):
            for sy in (-1, 1):
                parts.append(leg(st.leg, (sx * L / 2, sy * w / 2), top, 0.07, st))
        parts += [box((sx * L / 2, 0, top), (0.04, w, 0.06)) for sx in (-1, 1)]
        parts += [box((0, sy * w / 2, top), (L, 0.04, 0.06)) for sy in (-1, 1)]
        parts.append(slab((hx, 0, head / 2), (0.05, w, head), st, axis=0))
    elif s == 2:  # slatted head- and footboards
        for x, hh in ((hx, head), (-hx, frame + mat + 0.1)):
            parts += [box((x, sy * w / 2, hh / 2), (0.06, 0.06, hh)) for sy in (-1, 1)]
            n = int(rng.integers(4, 9))
            parts += [box((x, -w / 2 + w * (k + 0.5) / n, (frame + hh) / 2), (0.03, w / n * 0.5, hh - frame))
                      for k in range(n)]
            parts.append(box((x, 0, hh), (0.07, w + 0.06, 0.05)))
    else:  # an upholstered, rounded headboard
        parts.append(cushion((hx - 0.04, 0, head * 0.6), (0.14, w + 0.1, head * 0.85), 0.7))
    for k in range(1 if w < 1.3 else 2):  # pillows
        py = 0 if w < 1.3 else (k - 0.5) * w / 2
        parts.append(cushion((-L / 2 + 0.25, py, frame + mat + 0.06), (0.35, min(0.7, w * 0.45), 0.14), 0.3))
    return parts


def bathtub(rng, s, st):
    L, w, h = rng.uniform(1.5, 1.8), rng.uniform(0.7, 0.85), rng.uniform(0.5, 0.62)
    wall = rng.uniform(0.06, 0.12)
    if s == 0:  # built in: a rectangular tub in a block
        walls, outer = ring((0, 0, h / 2), (L, w), wall, h, Style(edge="sharp"))
        parts = walls + [plate((0, 0, 0.05), outer, 0.1)]
    elif s == 1:  # clawfoot: an oval tub on four feet
        walls, outer = ring((0, 0, 0.15 + h / 2), (L, w), wall, h, st, oval=True)
        parts = walls + [plate((0, 0, 0.2), outer, 0.1)]
        parts += [leg("turned", (sx * L * 0.35, sy * w * 0.3), 0.16, 0.08, st) for sx in (-1, 1) for sy in (-1, 1)]
    elif s == 2:  # freestanding rounded rectangle on a plinth, with a rolled rim
        walls, outer = ring((0, 0, h / 2 + 0.06), (L, w), wall, h, Style(edge="round", quad_segs=st.quad_segs))
        parts = walls + [plate((0, 0, 0.1), outer, 0.08), box((0, 0, 0.03), (L * 0.85, w * 0.8, 0.06))]
        parts.append(extrude(outer.difference(outer.buffer(-wall * 1.5)), 0.04, (0, 0, h + 0.08)))
    else:  # an oval basin let into a rectangular deck
        basin = affinity.scale(Point(0, 0).buffer(0.5, quad_segs=st.quad_segs + 2), L - 0.2, w - 0.15)
        deck = outline(-L / 2, -w / 2, L / 2, w / 2)
        parts = [extrude(deck.difference(basin), h, (0, 0, h / 2)), plate((0, 0, 0.05), deck, 0.1)]
    if rng.random() < 0.6:  # a tap
        parts.append(cylinder((-L / 2 + wall, 0, h + 0.15), 0.02, 0.2, st.sections))
    return parts


def chair(rng, s, st):
    w, d = rng.uniform(0.4, 0.55), rng.uniform(0.4, 0.55)
    seat, t = rng.uniform(0.42, 0.48), rng.uniform(0.03, 0.07)
    back = rng.uniform(0.35, 0.55)
    if s in (0, 1):
        parts = [slab((0, 0, seat - t / 2), (w, d, t), st)]
        parts += legs4(w, d, seat - t, 0.03, rng.uniform(0.03, 0.05), st)
        if s == 0:
            parts.append(slab((0, d / 2 - 0.02, seat + back / 2), (w, 0.04, back), st, axis=1))
        else:  # slats between posts, and arms
            parts += [box((sx * (w / 2 - 0.02), d / 2 - 0.02, seat + back / 2), (0.035, 0.035, back)) for sx in (-1, 1)]
            n = int(rng.integers(2, 6))
            parts += [box((-w / 2 + w * (k + 0.5) / n, d / 2 - 0.02, seat + back / 2), (w / (2.5 * n), 0.02, back * 0.8))
                      for k in range(n)]
            parts.append(box((0, d / 2 - 0.02, seat + back), (w, 0.04, 0.06)))
            if rng.random() < 0.5:
                parts += [box((sx * w / 2, 0, seat + 0.22), (0.04, d, 0.04)) for sx in (-1, 1)]
        return parts
    # shells: a moulded seat and back
    parts = [cushion((0, 0, seat - t / 2), (w, d, t + 0.03), 0.8),
             shell((0, d / 2 - 0.02, seat + back / 2), w, back, 0.025, rng.uniform(0.04, 0.1))]
    if s == 2:  # a cantilever: a tube frame sweeping down and forward
        r = 0.012
        for sx in (-1, 1):
            x = sx * w * 0.45
            parts += [cylinder((x, -d / 2, seat / 2), r, seat, st.sections),
                      cylinder((x, -0.1, 0.012), r, d + 0.1, st.sections, axis=1)]
        parts.append(cylinder((0, 0.1, 0.012), r, w * 0.9, st.sections, axis=0))
    else:  # an office chair: a star base, arms
        parts += star_base(seat - t, rng.uniform(0.25, 0.33), st)
        parts += [box((sx * (w / 2 + 0.03), 0, seat + 0.12), (0.05, d * 0.6, 0.03)) for sx in (-1, 1)]
        parts += [box((sx * (w / 2 + 0.03), 0, seat + 0.05), (0.03, 0.04, 0.13)) for sx in (-1, 1)]
    return parts


def bowl(rng, seat, r, elong, st, lift=0.0):
    """A toilet bowl: a revolved cup, stretched front to back, its rim at `seat`."""
    h = rng.uniform(0.2, 0.28)
    m = turned((0, 0, seat - h / 2), [0.55 * r, 0.8 * r, 0.95 * r, r], h, st.sections)
    m.apply_scale([1, elong, 1])
    m.apply_translation((0, -r * 0.3, 0))
    return [m, cushion((0, -r * 0.3, seat + 0.02), (2.1 * r, 2.1 * r * elong, 0.04), 0.3)]


def toilet(rng, s, st):
    r, seat, elong = rng.uniform(0.17, 0.22), rng.uniform(0.38, 0.45), rng.uniform(1.15, 1.45)
    tw, th = rng.uniform(0.35, 0.5), rng.uniform(0.3, 0.42)
    ty = r * elong * 0.7 + 0.1
    parts = bowl(rng, seat, r, elong, st)
    if s == 0:  # a floor toilet with a pedestal and a tank
        foot = turned((0, -0.02, (seat - 0.2) / 2), [0.65 * r, 0.5 * r, 0.45 * r], seat - 0.2, st.sections)
        foot.apply_scale([1, 1.3, 1])
        parts += [foot, slab((0, ty, seat + th / 2 - 0.05), (tw, 0.18, th), st)]
    elif s == 1:  # wall-hung: no pedestal, a flat cistern panel behind
        parts += [box((0, ty - 0.02, (seat - 0.25) / 2 + 0.25), (r * 1.4, 0.16, seat - 0.25 + 0.1)),
                  slab((0, ty + 0.05, seat + 0.3), (tw, 0.05, 0.7), st, axis=1)]
    elif s == 2:  # one-piece, skirted: a rounded block under the bowl, a low tank
        parts.append(slab((0, -r * 0.2, (seat - 0.1) / 2), (2 * r, 2 * r * elong, seat - 0.1), Style(
            edge="round", quad_segs=st.quad_segs)))
        parts.append(slab((0, ty, seat + th / 3), (tw, 0.2, th * 0.6), Style(edge="round", quad_segs=st.quad_segs)))
    else:  # a pedestal, a tall tank and the lid up
        parts.append(cylinder((0, -0.02, (seat - 0.2) / 2), 0.5 * r, seat - 0.2, st.sections))
        parts += [slab((0, ty, seat + th / 2 + 0.05), (tw, 0.16, th * 1.3), st),
                  slab((0, ty - 0.11, seat + 0.25), (2 * r, 0.03, 0.45), Style(edge="round"), axis=1)]
    return parts


def monitor(rng, s, st):
    w, h = rng.uniform(0.5, 0.8), rng.uniform(0.3, 0.5)
    t, stand = rng.uniform(0.015, 0.05), rng.uniform(0.08, 0.2)
    z = stand + h / 2
    if s == 2:  # curved panel on a round foot
        panel = [shell((0, 0, z), w, h, t, rng.uniform(0.05, 0.1), points=13)]
    else:
        panel = [slab((0, 0, z), (w, t, h), st, axis=1)]
    if s == 0:
        return panel + [box((0, t / 2 + 0.03, stand / 2 + 0.02), (0.06, 0.03, stand + 0.04)),
                        slab((0, 0.05, 0.01), (w * rng.uniform(0.3, 0.5), rng.uniform(0.15, 0.25), 0.02), st)]
    if s == 1:  # a CRT: a tapered back
        back = Polygon([(-w / 2, 0), (w / 2, 0), (w * 0.3, rng.uniform(0.25, 0.4)), (-w * 0.3, rng.uniform(0.25, 0.4))])
        m = extrude(back, h * 0.85, (0, 0, z))
        return panel + [m, box((0, 0.15, stand / 2), (w * 0.4, 0.25, stand))]
    if s == 2:
        return panel + [cylinder((0, 0.05, stand / 2 + 0.02), 0.02, stand + 0.04, st.sections),
                        disc((0, 0.05, 0.01), rng.uniform(0.1, 0.15), 0.02, st)]
    # an all-in-one: a chin below the screen and a slanted L-stand
    chin = rng.uniform(0.06, 0.12)
    leg_ = box((0, 0, 0), (0.15, 0.02, stand + h / 2))
    leg_.apply_transform(np.array([[1, 0, 0, 0], [0, 1, -0.35, 0], [0, 0, 1, 0], [0, 0, 0, 1.0]]))
    leg_.apply_translation((0, t / 2 + 0.08, (stand + h / 2) / 2))
    return panel + [slab((0, 0, stand - chin / 2), (w, t, chin), st, axis=1), leg_,
                    box((0, 0.12, 0.01), (0.2, 0.2, 0.02))]


CLASSES = ("bathtub", "bed", "chair", "desk", "dresser", "monitor", "night_stand", "sofa",
           "table", "toilet")
GENERATORS = {name: globals()[name] for name in CLASSES}
