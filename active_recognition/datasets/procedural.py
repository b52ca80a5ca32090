# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""An embedded benchmark: 10 furniture classes named after ModelNet10's (see `furniture`).

Every class has styles (combinations of two factors, e.g. a table's top and support) built from
trimesh's primitives and operations; the proportions come from real furniture's ranges, and
edges, legs and mesh resolution vary within a style. Splits: `train` and `test` hold the
training styles, `cross` the held-out combinations of every class (the cross-style test split: a
proxy for real objects). Shapes are upright (+Z) and face -Y, like
ModelNet; everything is deterministic in the seed.
"""
from __future__ import annotations

import numpy as np
import trimesh

from active_recognition.datasets.furniture import CLASSES, GENERATORS, styles
from active_recognition.datasets.parts import Style
from active_recognition.sensing.meshes import normalise


def make_shape(label: int, seed: int, held_out=False, style=None):
    """Build one shape of class `label` from `seed`: (vertices (V, 3) in [-0.5, 0.5]^3, faces).
    Its style is drawn from the training styles of the class (`held_out`: the held-out ones), or
    forced to `style` (a, b); the draw is made either way, so the rest of the shape agrees."""
    rng = np.random.default_rng(seed)
    name = CLASSES[label]
    options = styles(name, held_out)
    pick = options[int(rng.random() * len(options))]  # drawn even when forced
    pick = pick if style is None else tuple(style)
    mesh = trimesh.util.concatenate(GENERATORS[name](rng, *pick, Style.draw(rng)))
    return normalise(mesh.vertices).astype(np.float32), np.asarray(mesh.faces, dtype=np.int32)


def shape_seeds(seed: int, per_class: int, split: str, classes=len(CLASSES)):
    """Deterministic (label, seed) list of a split: train and test never share a seed."""
    offset = {"train": 0, "test": 1, "cross": 2, "val": 3}[split]
    ss = np.random.SeedSequence([seed, offset])
    seeds = ss.generate_state(per_class * classes, dtype=np.uint32)
    return [(i // per_class, int(s)) for i, s in enumerate(seeds)]


VERSION = 4  # bump when a generator changes, so caches are rebuilt
PER_CLASS = {"train": 200, "test": 50, "cross": 50}
SPLITS = tuple(PER_CLASS)  # a generated benchmark also has the cross-style test split


def generated(name, classes, make, version, split="train", cache_dir=None, seed=0, per_class=None,
              sizes=None, metres=False):
    """A generated benchmark as a ShapeDataset: `make(label, seed)` builds each shape; all meshes
    of a split are cached in one .npz under cache_dir/name. `sizes`: {split: objects per class}
    (default PER_CLASS), which also names the splits there are. `metres`: make also gives each
    shape's longest box edge in metres, as built, which the dataset then knows as its size."""
    from active_recognition.argument_checks import InputError
    from active_recognition.datasets.base import load_npz, save_npz_atomic, ShapeDataset

    sizes = PER_CLASS if sizes is None else sizes
    if split not in sizes:
        raise InputError(f"split of {name} must be one of {tuple(sizes)}, got {split!r}")
    per_class = sizes[split] if per_class is None else int(per_class)
    if per_class < 1:
        raise InputError(f"{name} per_class must be at least 1, got {per_class}")
    specs = shape_seeds(seed, per_class, split, len(classes))
    items = [(f"{classes[label]}/{s}", label) for label, s in specs]
    ds = ShapeDataset(name, list(classes), split, items, cache_dir=cache_dir)
    path = None
    if cache_dir is not None:
        from pathlib import Path
        path = Path(cache_dir) / name / f"v{version}-s{seed}-{split}-{per_class}.npz"
    keys = ("vertices", "faces", "vertex_offsets", "face_offsets") + (("edges",) if metres else ())
    cached = None if path is None else load_npz(path, keys)
    if cached is not None and len(cached[2]) == len(items) + 1:
        v, f, vo, fo = cached[:4]
        for i in range(len(items)):
            ds._meshes[i] = (v[vo[i]:vo[i + 1]], f[fo[i]:fo[i + 1]])
        return with_sizes(ds, cached[4]) if metres else ds
    built = [make(label, s) for label, s in specs]
    meshes = [m[:2] for m in built]
    edges = np.array([m[2] for m in built] if metres else [])
    ds._meshes = dict(enumerate(meshes))
    if path is not None:
        save_npz_atomic(path, vertices=np.concatenate([v for v, _ in meshes]),
                        faces=np.concatenate([f for _, f in meshes]),
                        vertex_offsets=np.cumsum([0] + [len(v) for v, _ in meshes]),
                        face_offsets=np.cumsum([0] + [len(f) for _, f in meshes]),
                        **({"edges": edges} if metres else {}))
    return with_sizes(ds, edges) if metres else ds


def with_sizes(ds, edges):
    """ds, knowing each item's size: its longest box edge `edges[i]` in metres."""
    ds.unit = 1.0
    ds._edges.update({source: float(e) for (source, _), e in zip(ds.items, edges)})
    return ds


def procedural(split="train", cache_dir=None, seed=0, per_class=None):
    """The procedural benchmark as a ShapeDataset (see `generated`); `cross` holds the held-out
    styles."""
    held_out = split == "cross"
    return generated("procedural", CLASSES, lambda label, s: make_shape(label, s, held_out),
                     VERSION, split, cache_dir, seed, per_class)
