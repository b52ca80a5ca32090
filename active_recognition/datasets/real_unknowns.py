# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""Real meshes of object classes outside ModelNet10 ("real unknowns"), for open-set recognition.

The manifest `real_unknowns.tsv` beside this file names, one row per mesh file, files of public
GitHub repositories at fixed commits (with their git blob hashes) and how they make objects: the
files of one `object` are merged and scaled by `unit` (metres per file unit) into metres. The
meshes are never committed: `python tools/fetch_real_unknowns.py --out DIR` rebuilds them as
DIR/<split>/<class>/<repository>__<object>.ply, in metres, and `real_unknowns(DIR, split)` opens
them. Three splits, from disjoint repositories and sharing no file: `train` (outliers for
training alone: train option real_outliers), `val` (where an operating point is chosen) and
`test` (read only for the final figures). `near` marks the furniture-like classes
that are none of the ten (shelves, cabinets, benches, stairs, kitchen appliances): the unknowns
most like the known classes.
"""
from __future__ import annotations

from functools import lru_cache
from pathlib import Path

from active_recognition.argument_checks import InputError
from active_recognition.datasets.base import ShapeDataset

MANIFEST = Path(__file__).with_name("real_unknowns.tsv")
COLUMNS = ("split", "repo", "commit", "path", "blob", "bytes", "class", "object", "unit", "near")
SPLITS = ("train", "val", "test")  # train: outliers for training alone (train option real_outliers)
FETCH = "python tools/fetch_real_unknowns.py --out DIR"  # the command that rebuilds the meshes


def read_manifest(path=MANIFEST):
    """The manifest's rows as dicts of COLUMNS (`bytes` and `near` int, `unit` float); lines
    starting with '#' are comments. InputError naming the file and line of a malformed row."""
    path = Path(path)
    try:
        lines = path.read_text(encoding="utf-8").splitlines()
    except OSError as e:
        raise InputError(f"real-unknowns manifest {path}: {e.strerror or e}") from None
    rows, header = [], False
    for n, line in enumerate(lines, 1):
        if not line.strip() or line.startswith("#"):
            continue
        fields = line.split("\t")
        if not header:
            if tuple(fields) != COLUMNS:
                raise InputError(f"{path}:{n}: the header must be the tab-separated columns {' '.join(COLUMNS)}")
            header = True
            continue
        if len(fields) != len(COLUMNS):
            raise InputError(f"{path}:{n}: {len(fields)} tab-separated columns, expected {len(COLUMNS)}")
        row = dict(zip(COLUMNS, fields))
        try:
            row.update(bytes=int(row["bytes"]), unit=float(row["unit"]), near=int(row["near"]))
        except ValueError:
            raise InputError(f"{path}:{n}: bytes, unit and near must be numbers") from None
        if row["split"] not in SPLITS or not row["unit"] > 0 or row["near"] not in (0, 1):
            raise InputError(f"{path}:{n}: split must be one of {', '.join(SPLITS)}, unit > 0, near 0 or 1")
        rows.append(row)
    if not header:
        raise InputError(f"{path}: no header line ({' '.join(COLUMNS)})")
    return rows


def ply_path(row) -> Path:
    """Where the object of manifest row `row` is written, relative to the root:
    <split>/<class>/<repository name>__<object>.ply."""
    return Path(row["split"], row["class"], f"{row['repo'].split('/')[-1]}__{row['object']}.ply")


@lru_cache
def near_classes(path=MANIFEST) -> frozenset:
    """The classes the manifest marks `near` (furniture-like, none of ModelNet10's ten)."""
    return frozenset(row["class"] for row in read_manifest(path) if row["near"])


def near(ds: ShapeDataset, i) -> bool:
    """Whether item i of a real_unknowns dataset is of a furniture-like class (marked near)."""
    return ds.classes[ds.items[i][1]] in near_classes()


def real_unknowns(root, split="test", cache_dir=None):
    """The rebuilt objects of `split` (`train`, `val` or `test`) under `root`, <root>/<split>/<class>/*.ply,
    classes sorted; the files are in metres (unit 1), so each item's size() is its box's longest
    edge in metres."""
    if split not in SPLITS:
        raise InputError(f"split of real_unknowns must be one of {', '.join(SPLITS)}, got {split!r}")
    if root is None or str(root) == "":
        raise InputError(f"the real_unknowns dataset needs its root folder, where {FETCH} rebuilds the meshes")
    if not Path(root).is_dir():
        raise InputError(f"real_unknowns root {root}: no such directory; rebuild the meshes with {FETCH}")
    base = Path(root) / split
    if not base.is_dir():
        raise InputError(f"real_unknowns root {root} has no {split}/ folder; rebuild the meshes with {FETCH}")
    classes = sorted(p.name for p in base.iterdir() if p.is_dir())
    items = [(p, label) for label, c in enumerate(classes) for p in sorted((base / c).glob("*.ply"))]
    if not items:
        raise InputError(f"real_unknowns root {root}: no mesh under {base}/<class>/*.ply; rebuild them with {FETCH}")
    return ShapeDataset("real_unknowns", classes, split, items, cache_dir=cache_dir, unit=1.0,
                        layout=f"real_unknowns root {root} ({base}/<class>/*.ply; rebuilt by {FETCH})")
