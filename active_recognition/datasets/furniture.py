# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""The procedural benchmark's ten classes, built from `parts`, each in styles that combine two
factors (a table: its top x its support; a chair: its base x its back).

A style is one combination, say a round top on a trestle. Within a style the proportions come
from real furniture's ranges (metres) and edges, legs and mesh resolution vary (`parts.Style`).
Some combinations of every class are held out (`held_out`): no training shape has them, though
each option of each factor appears in training with other options. The cross-style split tests
on them, a proxy for real objects, whose combinations a generator never matches. The designed
confusions stay: table/desk, night_stand/dresser, sofa/bed/bathtub, chair/toilet. Shapes stand on
z = 0 and face -y; every builder takes (rng, a, b, style) and returns a list of meshes.
"""
from __future__ import annotations

import numpy as np
from shapely import affinity
from shapely.geometry import Point, Polygon
from shapely.geometry import box as outline

from active_recognition.datasets.parts import (
    Style, box, cushion, cylinder, disc, extrude, leg, legs4, pedestal, plate, shell, slab, star_base,
    turned,
)


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


def table(rng, top, support, st):  # top: rect, round | support: legs, pedestal, trestle, shelf
    w, d = rng.uniform(0.8, 1.8), rng.uniform(0.6, 1.0)
    h, t = rng.uniform(0.7, 0.78), rng.uniform(0.02, 0.05)
    if top == 1:
        d = w * rng.uniform(0.6, 1.0)
        parts = [disc((0, 0, h - t / 2), 0.5, t, st, scale=(w, d))]
    else:
        parts = [slab((0, 0, h - t / 2), (w, d, t), st)]
    k = 0.7 if top == 1 else 1.0  # legs under a round top stand further in
    if support == 0:
        parts += legs4(w * k, d * k, h - t, rng.uniform(0.04, 0.1), rng.uniform(0.04, 0.08), st)
        if rng.random() < 0.6:  # aprons
            parts += [box((0, sy * (d * k / 2 - 0.06), h - t - 0.05), (w * k - 0.14, 0.02, 0.1))
                      for sy in (-1, 1)]
    elif support == 1:
        parts += pedestal(h - t, rng.uniform(0.04, 0.08), rng.uniform(0.2, 0.3) * w, st)
    elif support == 2:  # trestle: two end frames on feet and a stretcher
        for sx in (-1, 1):
            x = sx * (w * k / 2 - rng.uniform(0.1, 0.2))
            parts += [slab((x, 0, (h - t) / 2), (0.06, 0.12, h - t), st, axis=0),
                      box((x, 0, 0.03), (0.08, d * 0.8, 0.06)),
                      box((x, 0, h - t - 0.03), (0.08, d * 0.7, 0.05))]
        parts.append(box((0, 0, 0.25 * h), (w * k * 0.7, 0.05, 0.06)))
    else:  # legs with a shelf below
        parts += legs4(w * 0.7, d * 0.7, h - t, 0.03, rng.uniform(0.04, 0.07), st)
        parts.append(slab((0, 0, 0.2 * h), (w * 0.72, d * 0.72, 0.02), st))
    return parts


def desk(rng, base, extra, st):  # base: pedestal, two pedestals, panels, legs | extra: modesty, drawers, hutch
    w, d = rng.uniform(1.0, 1.8), rng.uniform(0.55, 0.85)
    h, t = rng.uniform(0.72, 0.77), rng.uniform(0.025, 0.05)
    parts = [slab((0, 0, h - t / 2), (w, d, t), st)]
    under, pw = h - t, rng.uniform(0.3, 0.45)

    def ped(side):  # a drawer pedestal under one end
        x = side * (w / 2 - pw / 2)
        return [box((x, 0, under / 2), (pw, d * 0.95, under))] + drawers(
            x, -d * 0.475, 0.03, pw, under - 0.05, 1, int(rng.integers(2, 5)), rng, st)
    if base == 0:
        side = rng.choice([-1, 1])
        parts += ped(side) + [leg(st.leg, (-side * (w / 2 - 0.05), sy * (d / 2 - 0.05)), under,
                                  0.05, st, (-side, sy)) for sy in (-1, 1)]
    elif base == 1:
        parts += ped(-1) + ped(1)
    elif base == 2:
        parts += [slab((sx * (w / 2 - 0.02), 0, under / 2), (0.04, d, under), st, axis=0)
                  for sx in (-1, 1)]
    else:
        parts += legs4(w, d, under, 0.04, 0.05, st)
    if extra == 0:  # a modesty panel at the back
        parts.append(box((0, d / 2 - 0.05, under * 0.6), (w * 0.9, 0.02, under * 0.5)))
    elif extra == 1:  # a row of drawers under the top
        n = int(rng.integers(1, 4))
        parts.append(box((0, 0, under - 0.06), (w * 0.45, d * 0.9, 0.12)))
        parts += drawers(0, -d * 0.45, under - 0.11, w * 0.45, 0.1, n, 1, rng, st)
    else:  # a hutch: shelves on the back of the top
        hh = rng.uniform(0.25, 0.45)
        parts += [box((sx * (w / 2 - 0.02), d / 2 - 0.12, h + hh / 2), (0.03, 0.22, hh)) for sx in (-1, 1)]
        parts += [box((0, d / 2 - 0.12, h + hh), (w, 0.24, 0.03)),
                  box((0, d / 2 - 0.02, h + hh / 2), (w, 0.02, hh))]
    return parts


def body(rng, st, shape, w, d, h, z0, cols, rows):
    """A carcass (a box, or a drum when shape is 1) from z0 to z0 + h, drawers on its front."""
    if shape == 1:
        return [cylinder((0, 0, z0 + h / 2), w / 2, h, st.sections),
                disc((0, 0, z0 + h + 0.015), w / 2 + 0.02, 0.03, st)] + drawers(
            0, -w / 2 + 0.005, z0 + 0.02, w * 0.6, h - 0.04, 1, rows, rng, st)
    return ([box((0, 0, z0 + h / 2), (w, d, h)),
             slab((0, 0, z0 + h + 0.015), (w + 0.03, d + 0.02, 0.03), st)]
            + drawers(0, -d / 2, z0 + 0.02, w * 0.94, h - 0.04, cols, rows, rng, st))


def night_stand(rng, shape, config, st):  # shape: box, drum | config: plinth, shelf on legs, cubby
    w, d, h = rng.uniform(0.4, 0.6), rng.uniform(0.35, 0.5), rng.uniform(0.4, 0.55)
    if config == 0:
        z0 = rng.uniform(0.03, 0.1)
        return ([box((0, 0, z0 / 2), (w * 0.9, d * 0.85, z0))]
                + body(rng, st, shape, w, d, h, z0, 1, int(rng.integers(1, 4))))
    if config == 1:  # one drawer on tall legs, an open shelf below
        z0 = rng.uniform(0.25, 0.35)
        return (legs4(w * 0.9, d * 0.9, z0, 0.03, 0.04, st) + body(rng, st, shape, w, d, h * 0.45, z0, 1, 1)
                + [slab((0, 0, 0.1), (w * 0.85, d * 0.85, 0.02), st)])
    z0 = rng.uniform(0.15, 0.25)  # two drawers under an open cubby, on legs
    parts = legs4(w * 0.9, d * 0.9, z0, 0.03, 0.04, st) + body(rng, st, shape, w, d, h * 0.6, z0, 1, 2)
    top = z0 + h * 0.6 + 0.03
    parts += [box((sx * (w * 0.45 - 0.01), 0, top + 0.1), (0.02, d * 0.8, 0.2)) for sx in (-1, 1)]
    return parts + [slab((0, 0, top + 0.21), (w * 0.9, d * 0.8, 0.02), st)]


def dresser(rng, shape, base, st):  # shape: wide, tall chest, sideboard | base: plinth, legs, legs + mirror
    d, z0 = rng.uniform(0.4, 0.55), rng.uniform(0.05, 0.15)
    if shape == 0:
        w, h = rng.uniform(0.9, 1.6), rng.uniform(0.7, 1.0)
        parts = body(rng, st, 0, w, d, h, z0, int(rng.integers(2, 4)), int(rng.integers(3, 6)))
    elif shape == 1:  # a tall chest: narrow, many rows, two half drawers on top
        w, h = rng.uniform(0.7, 0.95), rng.uniform(1.1, 1.4)
        parts = (body(rng, st, 0, w, d, h * 0.85, z0, 1, int(rng.integers(4, 7)))
                 + body(rng, st, 0, w, d, h * 0.15 - 0.03, z0 + h * 0.85 + 0.03, 2, 1))
    else:  # a sideboard: long and low, doors below a drawer row
        w, h = rng.uniform(1.4, 2.0), rng.uniform(0.7, 0.85)
        parts = body(rng, st, 0, w, d, h * 0.25, z0 + h * 0.75, 3, 1)
        parts.append(box((0, 0, z0 + h * 0.375), (w, d, h * 0.75)))
        doors = int(rng.integers(2, 5))
        for k in range(doors):
            x = -w / 2 + w * (k + 0.5) / doors
            parts += [slab((x, -d / 2 - 0.01, z0 + h * 0.375), (w / doors * 0.94, 0.02, h * 0.7), st, axis=1),
                      box((x + (0.35 if k % 2 else -0.35) * w / doors, -d / 2 - 0.03, z0 + h * 0.5),
                          (0.02, 0.02, 0.12))]
    if base == 0:
        parts.append(box((0, 0, z0 / 2), (w * 0.94, d * 0.9, z0)))
    else:
        parts += legs4(w, d, z0, 0.04, 0.05, st)
    if base == 2:  # a mirror on the back
        mh = rng.uniform(0.5, 0.8)
        parts.append(slab((0, d / 2 - 0.05, z0 + h + mh / 2 + 0.05), (w * 0.7, 0.03, mh), st, axis=1))
    return parts


def sofa(rng, arms, back, st):  # arms: box, rolled, slim | back: slab, curved with pillows
    L, d = rng.uniform(1.5, 2.4), rng.uniform(0.8, 1.0)
    seat, top = rng.uniform(0.38, 0.46), rng.uniform(0.75, 0.95)
    z0 = rng.uniform(0.1, 0.2) if rng.random() < 0.5 else 0.0  # on legs, or on the floor
    parts = [] if z0 == 0 else legs4(L * 0.95, d * 0.9, z0, 0.05, 0.04, st)
    arm_t = rng.uniform(0.12, 0.25)
    inner = L - 2 * arm_t
    parts.append(slab((0, 0, (z0 + seat - 0.12) / 2), (L, d, seat - 0.12 - z0), st))
    n = int(rng.integers(1, 4))
    for k in range(n):  # seat cushions
        parts.append(cushion((-inner / 2 + inner * (k + 0.5) / n, -0.06, seat - 0.06),
                             (inner / n * 0.97, d * 0.75, 0.14), rng.uniform(0.5, 0.9)))
    if back == 1:  # a curved back of pillows
        parts.append(shell((0, d / 2 - 0.08, (seat + top) / 2), L * 0.95, top - seat, 0.12, 0.08))
        parts += [cushion((-inner / 2 + inner * (k + 0.5) / n, d / 2 - 0.2, seat + 0.2),
                          (inner / n * 0.9, 0.18, 0.38), 0.4) for k in range(n)]
    else:
        parts.append(slab((0, d / 2 - 0.1, (seat + top) / 2), (L, 0.2, top - seat), st, axis=1))
    arm_h = seat + rng.uniform(0.12, 0.25)
    for sx in (-1, 1):
        x = sx * (L / 2 - arm_t / 2)
        if arms == 1:  # rolled arms
            parts += [box((x, 0, (z0 + arm_h) / 2), (arm_t, d, arm_h - z0)),
                      cylinder((x, 0, arm_h), arm_t / 2 + 0.02, d, st.sections, axis=1)]
        elif arms == 2:  # slim arms on the seat
            parts.append(slab((x, 0, (seat + arm_h) / 2), (arm_t * 0.6, d * 0.9, arm_h - seat + 0.1), st, axis=0))
        else:
            parts.append(slab((x, 0, (z0 + arm_h) / 2), (arm_t, d, arm_h - z0), st))
    if rng.random() < 0.3:  # a chaise on one end: an L
        side, cl, cw = rng.choice([-1, 1]), rng.uniform(0.6, 0.9), rng.uniform(0.6, 0.8)
        x = side * (L / 2 - cw / 2)
        parts += [box((x, -d / 2 - cl / 2, (seat - 0.12) / 2), (cw, cl, seat - 0.12)),
                  cushion((x, -d / 2 - cl / 2 + 0.05, seat - 0.06), (cw * 0.95, cl * 0.9, 0.14), 0.7)]
    return parts


def bed(rng, base, head, st):  # base: platform, rails on legs, upholstered | head: slab, posts, slats, padded
    L, w = rng.uniform(1.95, 2.2), rng.uniform(0.9, 1.9)
    frame, mat = rng.uniform(0.2, 0.35), rng.uniform(0.18, 0.3)
    parts = []
    if base == 0:
        parts.append(slab((0, 0, frame / 2), (L, w, frame), st))
    elif base == 1:
        parts += legs4(L, w, frame, 0.04, 0.07, st)
        parts += [box((0, sy * (w / 2 - 0.02), frame - 0.08), (L, 0.04, 0.16)) for sy in (-1, 1)]
    else:
        parts.append(cushion((0, 0, frame / 2), (L + 0.06, w + 0.06, frame), 0.9))
    parts.append(cushion((0, 0, frame + mat / 2), (L * 0.98, w * 0.97, mat), 0.85))
    hx = -L / 2 - 0.03
    hh = frame + mat + rng.uniform(0.25, 0.7)
    if head == 0:
        parts.append(slab((hx, 0, hh / 2), (0.06, w + 0.04, hh), st, axis=0))
    elif head == 1:  # four posts and a canopy frame
        top = rng.uniform(1.7, 2.1)
        parts += [leg(st.leg, (sx * L / 2, sy * w / 2), top, 0.07, st) for sx in (-1, 1) for sy in (-1, 1)]
        parts += [box((sx * L / 2, 0, top), (0.04, w, 0.06)) for sx in (-1, 1)]
        parts += [box((0, sy * w / 2, top), (L, 0.04, 0.06)) for sy in (-1, 1)]
        parts.append(slab((hx, 0, hh / 2), (0.05, w, hh), st, axis=0))
    elif head == 2:  # slatted head- and footboards
        for x, bh in ((hx, hh), (-hx, frame + mat + 0.1)):
            parts += [box((x, sy * w / 2, bh / 2), (0.06, 0.06, bh)) for sy in (-1, 1)]
            n = int(rng.integers(4, 9))
            parts += [box((x, -w / 2 + w * (k + 0.5) / n, (frame + bh) / 2), (0.03, w / n * 0.5, bh - frame))
                      for k in range(n)]
            parts.append(box((x, 0, bh), (0.07, w + 0.06, 0.05)))
    else:  # a padded, rounded headboard
        parts.append(cushion((hx - 0.04, 0, hh * 0.6), (0.14, w + 0.1, hh * 0.85), 0.7))
    for k in range(1 if w < 1.3 else 2):  # pillows
        py = 0 if w < 1.3 else (k - 0.5) * w / 2
        parts.append(cushion((-L / 2 + 0.25, py, frame + mat + 0.06), (0.35, min(0.7, w * 0.45), 0.14), 0.3))
    return parts


def tub_outline(shape, L, w, st):
    """A tub's outline: a rectangle, an oval or a rounded rectangle."""
    if shape == 1:
        return affinity.scale(Point(0, 0).buffer(0.5, quad_segs=st.quad_segs + 2), L, w)
    r = 0.25 * min(L, w) if shape == 2 else 0.0
    return outline(-L / 2 + r, -w / 2 + r, L / 2 - r, w / 2 - r).buffer(r, quad_segs=st.quad_segs + 1)


def bathtub(rng, shape, mount, st):  # shape: rect, oval, rounded | mount: block, feet, plinth, deck
    L, w, h = rng.uniform(1.5, 1.8), rng.uniform(0.7, 0.85), rng.uniform(0.5, 0.62)
    wall = rng.uniform(0.06, 0.12)
    outer = tub_outline(shape, L, w, st)
    if mount == 3:  # the basin let into a rectangular deck
        deck = outline(-L / 2 - 0.1, -w / 2 - 0.08, L / 2 + 0.1, w / 2 + 0.08)
        basin = outer.buffer(-wall)
        parts = [extrude(deck.difference(basin), h, (0, 0, h / 2)), plate((0, 0, 0.05), deck, 0.1)]
    else:
        z0 = (0.0, 0.15, 0.06)[mount]
        parts = [extrude(outer.difference(outer.buffer(-wall)), h, (0, 0, z0 + h / 2)),
                 plate((0, 0, z0 + 0.05), outer, 0.1)]
        if mount == 1:  # feet
            parts += [leg("turned", (sx * L * 0.35, sy * w * 0.3), z0 + 0.02, 0.08, st)
                      for sx in (-1, 1) for sy in (-1, 1)]
        elif mount == 2:  # a plinth and a rolled rim
            parts.append(box((0, 0, 0.03), (L * 0.8, w * 0.7, 0.06)))
            parts.append(extrude(outer.difference(outer.buffer(-wall * 1.5)), 0.04, (0, 0, z0 + h + 0.02)))
    if rng.random() < 0.6:  # a tap
        parts.append(cylinder((-L / 2 + wall, 0, h + 0.15), 0.02, 0.2, st.sections))
    return parts


def chair(rng, base, back, st):  # base: legs, cantilever, star | back: panel, slats, shell
    w, d = rng.uniform(0.4, 0.55), rng.uniform(0.4, 0.55)
    seat, t = rng.uniform(0.42, 0.48), rng.uniform(0.03, 0.07)
    bh = rng.uniform(0.35, 0.55)
    if rng.random() < 0.5:
        parts = [slab((0, 0, seat - t / 2), (w, d, t), st)]
    else:
        parts = [cushion((0, 0, seat - t / 2), (w, d, t + 0.03), rng.uniform(0.5, 0.9))]
    if base == 0:
        parts += legs4(w, d, seat - t, 0.03, rng.uniform(0.03, 0.05), st)
    elif base == 1:  # a cantilever: a tube frame sweeping down and forward
        for sx in (-1, 1):
            x = sx * w * 0.45
            parts += [cylinder((x, -d / 2, seat / 2), 0.012, seat, st.sections),
                      cylinder((x, -0.1, 0.012), 0.012, d + 0.1, st.sections, axis=1)]
        parts.append(cylinder((0, 0.1, 0.012), 0.012, w * 0.9, st.sections, axis=0))
    else:
        parts += star_base(seat - t, rng.uniform(0.25, 0.33), st)
    y = d / 2 - 0.02
    if back == 0:
        parts.append(slab((0, y, seat + bh / 2), (w, 0.04, bh), st, axis=1))
    elif back == 1:  # slats between posts
        parts += [box((sx * (w / 2 - 0.02), y, seat + bh / 2), (0.035, 0.035, bh)) for sx in (-1, 1)]
        n = int(rng.integers(2, 6))
        parts += [box((-w / 2 + w * (k + 0.5) / n, y, seat + bh / 2), (w / (2.5 * n), 0.02, bh * 0.8))
                  for k in range(n)]
        parts.append(box((0, y, seat + bh), (w, 0.04, 0.06)))
    else:
        parts.append(shell((0, y, seat + bh / 2), w, bh, 0.025, rng.uniform(0.04, 0.1)))
    if rng.random() < 0.4:  # arms
        parts += [box((sx * (w / 2 + 0.02), 0, seat + 0.2), (0.04, d * 0.8, 0.04)) for sx in (-1, 1)]
        parts += [box((sx * (w / 2 + 0.02), -d * 0.3, seat + 0.1), (0.03, 0.03, 0.2)) for sx in (-1, 1)]
    return parts


def toilet(rng, mount, tank, st):  # mount: pedestal, wall-hung, skirted | tank: box, panel, low, tall
    r, seat, elong = rng.uniform(0.17, 0.22), rng.uniform(0.38, 0.45), rng.uniform(1.15, 1.45)
    tw, th = rng.uniform(0.35, 0.5), rng.uniform(0.3, 0.42)
    ty = r * elong * 0.7 + 0.1
    cup = turned((0, 0, seat - 0.12), [0.55 * r, 0.8 * r, 0.95 * r, r], 0.24, st.sections)
    cup.apply_scale([1, elong, 1])
    cup.apply_translation((0, -r * 0.3, 0))
    parts = [cup, cushion((0, -r * 0.3, seat + 0.02), (2.1 * r, 2.1 * r * elong, 0.04), 0.3)]
    soft = Style(edge="round", quad_segs=st.quad_segs)
    if mount == 0:
        foot = turned((0, -0.02, (seat - 0.2) / 2), [0.65 * r, 0.5 * r, 0.45 * r], seat - 0.2, st.sections)
        foot.apply_scale([1, 1.3, 1])
        parts.append(foot)
    elif mount == 1:  # wall-hung: a block from the wall, off the floor
        parts.append(box((0, ty - 0.05, seat - 0.12), (r * 1.4, 0.2, 0.2)))
    else:  # skirted: a rounded block under the bowl
        parts.append(slab((0, -r * 0.2, (seat - 0.1) / 2), (2 * r, 2 * r * elong, seat - 0.1), soft))
    if tank == 0:
        parts.append(slab((0, ty, seat + th / 2 - 0.05), (tw, 0.18, th), st))
    elif tank == 1:  # a flat cistern panel
        parts.append(slab((0, ty + 0.05, seat + 0.3), (tw, 0.05, 0.7), st, axis=1))
    elif tank == 2:  # a low rounded tank
        parts.append(slab((0, ty, seat + th / 3), (tw, 0.2, th * 0.6), soft))
    else:  # a tall tank and the lid up
        parts += [slab((0, ty, seat + th / 2 + 0.05), (tw, 0.16, th * 1.3), st),
                  slab((0, ty - 0.11, seat + 0.25), (2 * r, 0.03, 0.45), soft, axis=1)]
    return parts


def monitor(rng, panel, stand, st):  # panel: flat, curved, chin, CRT | stand: rect foot, round foot, L
    w, h = rng.uniform(0.5, 0.8), rng.uniform(0.3, 0.5)
    t, lift = rng.uniform(0.015, 0.05), rng.uniform(0.08, 0.2)
    z = lift + h / 2
    if panel == 1:
        parts = [shell((0, 0, z), w, h, t, rng.uniform(0.05, 0.1), points=13)]
    else:
        parts = [slab((0, 0, z), (w, t, h), st, axis=1)]
    if panel == 2:  # a chin below the screen
        chin = rng.uniform(0.06, 0.12)
        parts.append(slab((0, 0, lift - chin / 2), (w, t + 0.01, chin), st, axis=1))
    elif panel == 3:  # a CRT: a tapered back
        deep = rng.uniform(0.25, 0.4)
        back = Polygon([(-w / 2, 0), (w / 2, 0), (w * 0.3, deep), (-w * 0.3, deep)])
        parts.append(extrude(back, h * 0.85, (0, 0, z)))
    y = t / 2 + (0.2 if panel == 3 else 0.03)
    if stand == 2:  # a slanted L-stand
        arm = box((0, 0, 0), (0.15, 0.02, lift + h / 2))
        arm.apply_transform(np.array([[1, 0, 0, 0], [0, 1, -0.35, 0], [0, 0, 1, 0], [0, 0, 0, 1.0]]))
        arm.apply_translation((0, y + 0.06, (lift + h / 2) / 2))
        return parts + [arm, box((0, y + 0.1, 0.01), (0.2, 0.2, 0.02))]
    parts.append(box((0, y, lift / 2 + 0.02), (0.06, 0.03, lift + 0.04)) if stand == 0 else
                 cylinder((0, y, lift / 2 + 0.02), 0.02, lift + 0.04, st.sections))
    if stand == 0:
        parts.append(slab((0, y, 0.01), (w * rng.uniform(0.3, 0.5), rng.uniform(0.15, 0.25), 0.02), st))
    else:
        parts.append(disc((0, y, 0.01), rng.uniform(0.1, 0.15), 0.02, st))
    return parts


CLASSES = ("bathtub", "bed", "chair", "desk", "dresser", "monitor", "night_stand", "sofa",
           "table", "toilet")
GENERATORS = {name: globals()[name] for name in CLASSES}
# options per factor (a, b) of each class, in the order of the builders' comments
FACTORS = {"bathtub": (3, 4), "bed": (3, 4), "chair": (3, 3), "desk": (4, 3), "dresser": (3, 3),
           "monitor": (4, 3), "night_stand": (2, 3), "sofa": (3, 2), "table": (2, 4), "toilet": (3, 4)}


def styles(name, held_out=False):
    """The (a, b) combinations of a class: held out are those with (a + b) % n == n - 1 (n the
    larger factor), which leaves every option of both factors in the training styles."""
    na, nb = FACTORS[name]
    n = max(na, nb)
    return [(a, b) for a in range(na) for b in range(nb) if ((a + b) % n == n - 1) == held_out]
