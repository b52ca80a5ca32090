"""ModelNet10 / ModelNet40: root/<class>/{train,test}/*.off, the official split."""
from __future__ import annotations

from ..validation import InputError
from .base import SPLITS, ShapeDataset, check_root, check_split


def modelnet(root, split="train", cache_dir=None):
    check_split(split)
    root = check_root(root, "modelnet")
    # every class with either split, so a class missing from one split keeps its label there
    classes = sorted(p.name for p in root.iterdir() if any((p / s).is_dir() for s in SPLITS))
    if not classes:
        raise InputError(f"modelnet root {root} has no <class>/train/ or <class>/test/ folders")
    items = [(p, label) for label, c in enumerate(classes) if (root / c / split).is_dir()
             for p in sorted((root / c / split).glob("*.off"))]
    return ShapeDataset("modelnet", classes, split, items, cache_dir=cache_dir,
                        layout=f"modelnet root {root} ({root}/<class>/{split}/*.off)")
