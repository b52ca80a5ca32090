# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""Shape datasets: ModelNet, ShapeNetCore, a plain folder, the embedded benchmarks (procedural,
twins) and the objects of no known class for open-set recognition: generated (unknowns) or real meshes
rebuilt from public repositories (real_unknowns); shapes (a split as rendered scenes) and augment
(what a robot's object frame and camera get wrong, drawn per training episode). The datasets layer
sits above the runtime: it imports sensing, model and the top-level foundation modules, and nothing
a robot runs imports it (test/test_layers.py)."""
from __future__ import annotations

import warnings
from dataclasses import replace

import numpy as np

from active_recognition.argument_checks import InputError
from active_recognition.datasets.base import ShapeDataset, default_cache_dir
from active_recognition.datasets.folder import folder
from active_recognition.datasets.modelnet import modelnet
from active_recognition.datasets.procedural import procedural
from active_recognition.datasets.real_unknowns import real_unknowns
from active_recognition.datasets.shapenet import shapenet
from active_recognition.datasets.twins import twins
from active_recognition.datasets.unknowns import unknowns

NAMES = ("procedural", "twins", "modelnet", "shapenet", "folder")
GENERATED = {"procedural": procedural, "twins": twins}
# objects of no known class (open-set recognition), with a val split of their own, not a tenth
# of train; opened by name like the others, but no model trains on them. unknowns are generated,
# real_unknowns read from files under a root (tools/fetch_real_unknowns.py rebuilds them)
OPEN_SET = {"unknowns": unknowns, "real_unknowns": real_unknowns}
LOADERS = {"modelnet": modelnet, "shapenet": shapenet, "folder": folder,  # read from a root folder
           "real_unknowns": real_unknowns}


SPLITS = ("train", "val", "test", "cross")  # cross: a generated benchmark's held-out styles
VAL_FRACTION, VAL_SEED = 0.1, 0  # the validation split: a seeded tenth of each class of train


def open_dataset(name, root=None, split="train", cache_dir=None, validate=True, **kwargs):
    """Open a split of a dataset by name; file datasets are validated (bad files skipped).

    `train` is the dataset's training split less `val`, a seeded VAL_FRACTION of each class of
    it (validation_split): every choice (epoch, settings, fixed path, default planner) is made
    on `val`, and `test` is read only for the final tables."""
    return open_splits(name, root, (split,), cache_dir, validate, **kwargs)[split]


def open_splits(name, root=None, splits=("train", "val"), cache_dir=None, validate=True, **kwargs):
    """{split: dataset} for several splits, each of the dataset's own splits read once (`train`
    and `val` are carved from one read of its training split)."""
    bad = [s for s in splits if s not in SPLITS]
    if bad:
        raise InputError(f"split must be one of {', '.join(SPLITS)}, got {bad[0]!r}")
    read = {}
    carved = ("train", "val") if name not in OPEN_SET else ()
    for split in splits:
        source = "train" if split in carved else split
        if source not in read:
            read[source] = read_split(name, root, source, cache_dir, validate, **kwargs)
    return {s: validation_split(copy_of(read["train"]), s) if s in carved else read[s]
            for s in splits}


def copy_of(ds: ShapeDataset):
    """A dataset of the same items, to keep part of (its meshes shared, not copied)."""
    return replace(ds, items=list(ds.items), skipped=list(ds.skipped), _meshes=dict(ds._meshes))


def read_split(name, root, source, cache_dir=None, validate=True, **kwargs):
    """One of the dataset's own splits (train, test, cross), as its loader reads it."""
    made = {**GENERATED, **OPEN_SET}
    if name in made and name not in LOADERS:
        if root:
            raise InputError(f"the {name} dataset is generated: it takes no root folder "
                             f"(got {root}); roots are for {', '.join(LOADERS)}")
        return made[name](source, cache_dir=cache_dir, **kwargs)
    if name not in LOADERS:
        raise InputError(f"dataset must be one of {', '.join(NAMES)}, got {name!r}")
    if source == "cross" and name not in OPEN_SET:  # an open-set loader names its own splits
        raise InputError(f"the cross split (held-out styles) is a generated benchmark's; "
                         f"{name} has train, val and test")
    ds = LOADERS[name](root, source, cache_dir=cache_dir, **kwargs)
    return ds.validate() if validate else ds


def validation_split(ds: ShapeDataset, split, fraction=VAL_FRACTION, seed=VAL_SEED):
    """The `val` or the `train` part of a training split `ds`: `val` holds a seeded `fraction`
    of each class (rounded: none of a class of 5 or fewer), `train` the rest, both in the
    split's order."""
    labels = ds.labels()
    held = np.zeros(len(ds), dtype=bool)
    for label in np.unique(labels):
        idx = np.flatnonzero(labels == label)
        n = round(fraction * len(idx))
        held[np.random.default_rng([seed, int(label)]).choice(idx, n, replace=False)] = True
    ds.keep(np.flatnonzero(held if split == "val" else ~held))
    ds.split = split
    if split == "val" and not len(ds) and len(labels):
        warnings.warn(f"{ds.name}: the validation split is empty (a tenth of each class of train, rounded: "
                      f"no class has 6 objects): training reports no per-epoch figures, and nothing can be "
                      f"chosen on it")
    return ds


def subset_with_every_class(labels, n, seed):
    """Sorted indices of a seeded sample of n of the objects with these labels, every class in it:
    the first n of a seeded order, where each class's first object in that order is moved in if it
    falls later (so where the first n hold every class, it is exactly them)."""
    labels = np.asarray(labels)
    classes = np.unique(labels)
    if n < len(classes):
        raise InputError(f"max_shapes = {n} cannot hold an object of each of the {len(classes)} classes")
    order = np.random.default_rng(seed).permutation(len(labels))
    first = {int(order[np.argmax(labels[order] == c)]) for c in classes}
    rest = [int(i) for i in order if int(i) not in first]
    return np.sort(np.array(sorted(first) + rest[:max(0, n - len(first))], dtype=np.int64))


def describe(name, root=None, cache_dir=None):
    """Print a dataset's class counts per split and its skipped files (with why); warn of a class
    a split lacks. -> {split: dataset}. InputError, saying what was looked for, when empty."""
    import sys

    splits = open_splits(name, root, ("train", "val", "test"), cache_dir)
    classes = splits["train"].classes
    width = max(len(c) for c in classes + ["class"])
    print(f"{name}: {len(classes)} classes")
    print(f"{'class':<{width}}" + "".join(f"  {s:>6}" for s in splits))
    counts = {s: ds.class_counts() for s, ds in splits.items()}
    for i, c in enumerate(classes):
        print(f"{c:<{width}}" + "".join(f"  {counts[s][i]:>6}" for s in splits))
    print(f"{'total':<{width}}" + "".join(f"  {len(ds):>6}" for ds in splits.values()))
    skipped = splits["train"].skipped + splits["test"].skipped
    print(f"skipped {len(skipped)} file(s)")
    for path, reason in skipped:
        print(f"  {path}: {reason}")
    for s, ds in splits.items():
        missing = [c for c, n in zip(classes, counts[s]) if n == 0]
        if missing and len(ds):
            print(f"warning: no {s} objects for class(es) {', '.join(missing)}", file=sys.stderr)
    if not len(splits["train"]) and not len(splits["test"]):  # say what was looked for
        splits["test"].skipped = skipped
        splits["test"].require_objects("objects (train or test)")
    return splits


__all__ = ["ShapeDataset", "open_dataset", "open_splits", "validation_split", "default_cache_dir", "describe",
           "NAMES", "SPLITS"]
