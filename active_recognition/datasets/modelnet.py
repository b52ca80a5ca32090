# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""ModelNet10 / ModelNet40: root/<class>/{train,test}/*.off, the official split."""
from __future__ import annotations

from active_recognition.argument_checks import InputError
from active_recognition.datasets.base import SPLITS, ShapeDataset, check_root, check_split

INCH = 0.0254  # metres


def modelnet(root, split="train", cache_dir=None):
    check_split(split)
    root = check_root(root, "modelnet")
    # every class with either split, so a class missing from one split keeps its label there
    classes = sorted(p.name for p in root.iterdir() if any((p / s).is_dir() for s in SPLITS))
    if not classes:
        raise InputError(f"modelnet root {root} has no <class>/train/ or <class>/test/ folders")
    items = [(p, label) for label, c in enumerate(classes) if (root / c / split).is_dir()
             for p in sorted((root / c / split).glob("*.off"))]
    # ModelNet's files are in inches: the median longest edge of a bed is 87 units (2.2 m), of a
    # chair 37 (0.94 m), of a night stand 27 (0.70 m)
    return ShapeDataset("modelnet", classes, split, items, cache_dir=cache_dir, unit=INCH,
                        layout=f"modelnet root {root} ({root}/<class>/{split}/*.off)")
