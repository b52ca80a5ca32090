# Copyright 2026 active_recognition maintainers
#
# Licensed under the Apache License, Version 2.0 (the "License");
# you may not use this file except in compliance with the License.
# You may obtain a copy of the License at
#
#     http://www.apache.org/licenses/LICENSE-2.0
#
# Unless required by applicable law or agreed to in writing, software
# distributed under the License is distributed on an "AS IS" BASIS,
# WITHOUT WARRANTIES OR CONDITIONS OF ANY KIND, either express or implied.
# See the License for the specific language governing permissions and
# limitations under the License.

"""An embedded benchmark: 10 furniture classes named after ModelNet10's, built from primitives.

Each class is a parametric generator with intra-class variety (proportions, part counts, optional
parts, leg shapes, thicknesses). Pairs are designed to look alike from some views and differ from
others: table/desk (same top; a desk has a drawer pedestal and a modesty panel underneath),
night_stand/dresser (same cabinet; drawer layout and proportions differ on the front), sofa/bed/
bathtub (long low boxes; back, headboard or a hollow), chair/toilet (seat and back; legs or a
pedestal and tank), monitor (a thin slab on a stand). Shapes are upright (+Z) and face -Y, like
ModelNet; everything is deterministic in the seed.
"""
from __future__ import annotations

import numpy as np
import trimesh

from ..meshes import normalise

CLASSES = ("bathtub", "bed", "chair", "desk", "dresser", "monitor", "night_stand", "sofa",
           "table", "toilet")


def box(center, size):
    m = trimesh.creation.box(extents=size)
    m.apply_translation(center)
    return m


def cylinder(center, radius, height, sections=16):
    m = trimesh.creation.cylinder(radius=radius, height=height, sections=sections)
    m.apply_translation(center)
    return m


def legs(rng, width, depth, height, inset, thick=None, round_=None):
    """Four legs under a (width x depth) top, their tops at `height`."""
    thick = thick if thick is not None else rng.uniform(0.03, 0.07) * max(width, depth)
    round_ = rng.random() < 0.4 if round_ is None else round_
    parts = []
    for sx in (-1, 1):
        for sy in (-1, 1):
            c = (sx * (width / 2 - inset), sy * (depth / 2 - inset), height / 2)
            parts.append(cylinder(c, thick / 2, height) if round_ else
                         box(c, (thick, thick, height)))
    return parts


def table(rng):
    w, d = rng.uniform(0.9, 1.6), rng.uniform(0.5, 1.0)
    h, top = rng.uniform(0.55, 0.8), rng.uniform(0.03, 0.07)
    parts = [box((0, 0, h - top / 2), (w, d, top))]
    if rng.random() < 0.2:  # pedestal table
        parts += [cylinder((0, 0, (h - top) / 2), 0.06, h - top), box((0, 0, 0.02), (0.5 * w, 0.5 * d, 0.04))]
    else:
        parts += legs(rng, w, d, h - top, rng.uniform(0.03, 0.1))
        if rng.random() < 0.4:  # apron
            parts.append(box((0, -d / 2 + 0.05, h - top - 0.04), (w * 0.9, 0.02, 0.08)))
    return parts


def desk(rng):
    w, d = rng.uniform(0.9, 1.6), rng.uniform(0.5, 1.0)
    h, top = rng.uniform(0.55, 0.8), rng.uniform(0.03, 0.07)
    parts = [box((0, 0, h - top / 2), (w, d, top))]
    pw = rng.uniform(0.25, 0.4) * w
    side = rng.choice([-1, 1])
    parts.append(box((side * (w / 2 - pw / 2), 0, (h - top) / 2), (pw, d * 0.95, h - top)))
    for k in range(int(rng.integers(2, 5))):  # drawer fronts on the pedestal
        z = (h - top) * (k + 0.5) / 4
        parts.append(box((side * (w / 2 - pw / 2), -d * 0.475 - 0.01, z), (pw * 0.85, 0.02, 0.12)))
    other = -side
    if rng.random() < 0.5:
        parts.append(box((other * (w / 2 - 0.03), 0, (h - top) / 2), (0.04, d * 0.9, h - top)))
    else:
        for sy in (-1, 1):
            parts.append(box((other * (w / 2 - 0.05), sy * (d / 2 - 0.05), (h - top) / 2),
                             (0.05, 0.05, h - top)))
    if rng.random() < 0.7:  # modesty panel at the back
        parts.append(box((0, d / 2 - 0.03, h * 0.6), (w * 0.9, 0.02, h * 0.5)))
    return parts


def cabinet(rng, w, d, h, columns, rows):
    parts = [box((0, 0, h / 2 + 0.05), (w, d, h))]
    if rng.random() < 0.5:
        parts += legs(rng, w, d, 0.06, 0.04, thick=0.05)
    cw, rh = w / columns, h / rows
    for c in range(columns):
        for r in range(rows):
            x, z = -w / 2 + cw * (c + 0.5), 0.05 + rh * (r + 0.5)
            parts.append(box((x, -d / 2 - 0.012, z), (cw * 0.88, 0.025, rh * 0.8)))
            if rng.random() < 0.6:  # handle
                parts.append(box((x, -d / 2 - 0.035, z), (cw * 0.25, 0.025, 0.025)))
    return parts


def night_stand(rng):
    w, d, h = rng.uniform(0.4, 0.6), rng.uniform(0.35, 0.5), rng.uniform(0.45, 0.7)
    parts = cabinet(rng, w, d, h, 1, int(rng.integers(1, 4)))
    if rng.random() < 0.3:  # open shelf on top
        parts.append(box((0, 0, h + 0.1), (w, d, 0.03)))
    return parts


def dresser(rng):
    w, d, h = rng.uniform(0.8, 1.5), rng.uniform(0.4, 0.55), rng.uniform(0.6, 1.1)
    parts = cabinet(rng, w, d, h, int(rng.integers(2, 4)), int(rng.integers(3, 6)))
    if rng.random() < 0.3:  # mirror
        parts.append(box((0, d / 2 - 0.03, h + 0.45), (w * 0.8, 0.03, 0.7)))
    return parts


def long_base(rng):
    return rng.uniform(1.6, 2.2), rng.uniform(0.8, 1.3)


def sofa(rng):
    L, d = long_base(rng)
    seat = rng.uniform(0.35, 0.5)
    back_h, back_t = rng.uniform(0.35, 0.6), rng.uniform(0.12, 0.25)
    parts = [box((0, 0, seat / 2), (L, d, seat)),
             box((0, d / 2 - back_t / 2, seat + back_h / 2), (L, back_t, back_h))]
    arm_h = rng.uniform(0.1, 0.3)
    if rng.random() < 0.85:
        arm_t = rng.uniform(0.1, 0.22)
        for s in (-1, 1):
            parts.append(box((s * (L / 2 - arm_t / 2), 0, seat + arm_h / 2), (arm_t, d, arm_h)))
    for k in range(int(rng.integers(1, 4))):  # seat cushions
        cw = L / 3
        parts.append(box((-L / 2 + cw * (k + 0.5) + 0.1 * (k == 0), -0.05, seat + 0.04),
                         (cw * 0.9, d * 0.7, 0.08)))
    return parts


def bed(rng):
    L, d = long_base(rng)
    d *= rng.uniform(1.0, 1.6)
    base = rng.uniform(0.3, 0.5)
    parts = [box((0, 0, base / 2 + 0.1), (L, d, base))]
    parts += legs(rng, L, d, 0.12, 0.05, thick=0.08)
    head_h = rng.uniform(0.3, 0.8)
    parts.append(box((-L / 2 - 0.03, 0, (base + head_h) / 2 + 0.05), (0.06, d, base + head_h)))
    if rng.random() < 0.5:  # footboard
        parts.append(box((L / 2 + 0.03, 0, base / 2 + 0.15), (0.06, d, base + 0.1)))
    for k in range(int(rng.integers(1, 3))):  # pillows
        py = (k - 0.5) * d / 2 if d > 1.2 else 0
        parts.append(box((-L / 2 + 0.25, py, base + 0.16), (0.3, d * 0.4, 0.1)))
    return parts


def bathtub(rng):
    L, d = long_base(rng)
    d *= rng.uniform(0.6, 0.9)
    h, t = rng.uniform(0.45, 0.65), rng.uniform(0.06, 0.14)
    parts = [box((0, 0, 0.05), (L, d, 0.1))]
    for s in (-1, 1):  # walls around a hollow
        parts.append(box((s * (L / 2 - t / 2), 0, h / 2), (t, d, h)))
        parts.append(box((0, s * (d / 2 - t / 2), h / 2), (L, t, h)))
    if rng.random() < 0.5:  # faucet
        parts.append(cylinder((-L / 2 + t, 0, h + 0.08), 0.025, 0.16))
    if rng.random() < 0.3:  # feet
        parts += legs(rng, L * 0.9, d * 0.9, 0.06, 0.05, thick=0.07)
    return parts


def chair(rng):
    w, d = rng.uniform(0.4, 0.6), rng.uniform(0.4, 0.6)
    seat_h, seat_t = rng.uniform(0.4, 0.5), rng.uniform(0.04, 0.08)
    parts = [box((0, 0, seat_h - seat_t / 2), (w, d, seat_t))]
    parts += legs(rng, w, d, seat_h - seat_t, rng.uniform(0.02, 0.05))
    back_h = rng.uniform(0.35, 0.6)
    if rng.random() < 0.5:
        parts.append(box((0, d / 2 - 0.03, seat_h + back_h / 2), (w, 0.05, back_h)))
    else:  # slatted back
        n = int(rng.integers(2, 5))
        for k in range(n):
            x = -w / 2 + w * (k + 0.5) / n
            parts.append(box((x, d / 2 - 0.03, seat_h + back_h / 2), (w / (2 * n), 0.04, back_h)))
        parts.append(box((0, d / 2 - 0.03, seat_h + back_h - 0.03), (w, 0.05, 0.06)))
    if rng.random() < 0.3:  # arms
        for s in (-1, 1):
            parts.append(box((s * w / 2, 0, seat_h + 0.2), (0.04, d, 0.04)))
    return parts


def toilet(rng):
    bowl_r, seat_h = rng.uniform(0.18, 0.24), rng.uniform(0.38, 0.45)
    elong = rng.uniform(1.1, 1.4)
    bowl = cylinder((0, 0, seat_h - 0.1), 1.0, 0.2, sections=20)
    bowl.apply_scale([bowl_r, bowl_r * elong, 1.0])
    bowl.apply_translation([0, -bowl_r * 0.3, -0.1 * 0 + (seat_h - 0.1) * 0])
    ped = cylinder((0, 0, (seat_h - 0.2) / 2), 1.0, seat_h - 0.2, sections=16)
    ped.apply_scale([bowl_r * 0.55, bowl_r * 0.7, 1.0])
    parts = [bowl, ped, box((0, -bowl_r * 0.3, seat_h + 0.01), (bowl_r * 1.9, bowl_r * 2 * elong, 0.02))]
    tank_w, tank_h = rng.uniform(0.35, 0.5), rng.uniform(0.3, 0.45)
    ty = bowl_r * elong * 0.7 + 0.09
    if rng.random() < 0.8:
        parts.append(box((0, ty, seat_h + tank_h / 2 - 0.05), (tank_w, 0.18, tank_h)))
    else:  # wall-hung tank / seat lid up
        parts.append(box((0, ty - 0.05, seat_h + 0.25), (bowl_r * 1.9, 0.04, 0.5)))
    return parts


def monitor(rng):
    w, h = rng.uniform(0.5, 0.9), rng.uniform(0.3, 0.55)
    t = rng.uniform(0.02, 0.06)
    stand = rng.uniform(0.08, 0.25)
    parts = [box((0, 0, stand + h / 2), (w, t, h))]
    if rng.random() < 0.3:  # CRT-style back
        parts.append(box((0, t / 2 + 0.1, stand + h / 2), (w * 0.6, 0.2, h * 0.6)))
    parts.append(box((0, t / 2 + 0.03, stand / 2 + 0.01), (0.06, 0.04, stand + 0.02)))
    base_w = rng.uniform(0.2, 0.4) * w / 0.5
    parts.append(box((0, t / 2 + 0.03, 0.01), (base_w * 0.6, rng.uniform(0.15, 0.25), 0.02)))
    return parts


GENERATORS = {name: globals()[name] for name in CLASSES}


def make_shape(label: int, seed: int):
    """Build one shape of class `label` from `seed`: (vertices (V, 3) in [-0.5, 0.5]^3, faces)."""
    rng = np.random.default_rng(seed)
    mesh = trimesh.util.concatenate(GENERATORS[CLASSES[label]](rng))
    return normalise(mesh.vertices).astype(np.float32), np.asarray(mesh.faces, dtype=np.int32)


def shape_seeds(seed: int, per_class: int, split: str, classes=len(CLASSES)):
    """Deterministic (label, seed) list of a split: train and test never share a seed."""
    offset = {"train": 0, "test": 1}[split]
    ss = np.random.SeedSequence([seed, offset])
    seeds = ss.generate_state(per_class * classes, dtype=np.uint32)
    return [(i // per_class, int(s)) for i, s in enumerate(seeds)]


VERSION = 1  # bump when a generator changes, so caches are rebuilt
PER_CLASS = {"train": 200, "test": 50}


def generated(name, classes, make, version, split="train", cache_dir=None, seed=0, per_class=None):
    """A generated benchmark as a ShapeDataset: `make(label, seed)` builds each shape; all meshes
    of a split are cached in one .npz under cache_dir/name."""
    from ..validation import InputError
    from .base import ShapeDataset, check_split, load_npz, save_npz_atomic

    check_split(split)
    per_class = PER_CLASS[split] if per_class is None else int(per_class)
    if per_class < 1:
        raise InputError(f"{name} per_class must be at least 1, got {per_class}")
    specs = shape_seeds(seed, per_class, split, len(classes))
    items = [(f"{classes[label]}/{s}", label) for label, s in specs]
    ds = ShapeDataset(name, list(classes), split, items, cache_dir=cache_dir)
    path = None
    if cache_dir is not None:
        from pathlib import Path
        path = Path(cache_dir) / name / f"v{version}-s{seed}-{split}-{per_class}.npz"
    keys = ("vertices", "faces", "vertex_offsets", "face_offsets")
    cached = None if path is None else load_npz(path, keys)
    if cached is not None and len(cached[2]) == len(items) + 1:
        v, f, vo, fo = cached
        for i in range(len(items)):
            ds._meshes[i] = (v[vo[i]:vo[i + 1]], f[fo[i]:fo[i + 1]])
        return ds
    meshes = [make(label, s) for label, s in specs]
    ds._meshes = dict(enumerate(meshes))
    if path is not None:
        save_npz_atomic(path, vertices=np.concatenate([v for v, _ in meshes]),
                        faces=np.concatenate([f for _, f in meshes]),
                        vertex_offsets=np.cumsum([0] + [len(v) for v, _ in meshes]),
                        face_offsets=np.cumsum([0] + [len(f) for _, f in meshes]))
    return ds


def procedural(split="train", cache_dir=None, seed=0, per_class=None):
    """The procedural benchmark as a ShapeDataset (see `generated`)."""
    return generated("procedural", CLASSES, make_shape, VERSION, split, cache_dir, seed, per_class)
