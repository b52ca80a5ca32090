"""ModelNet10 / ModelNet40: root/<class>/{train,test}/*.off, the official split."""
from __future__ import annotations

from .base import ShapeDataset, check_root, check_split


def modelnet(root, split="train", cache_dir=None):
    check_split(split)
    root = check_root(root, "modelnet")
    classes = sorted(p.name for p in root.iterdir() if (p / split).is_dir())
    if not classes:
        raise ValueError(f"modelnet root {root} has no <class>/{split}/ folders")
    items = [(p, label) for label, c in enumerate(classes)
             for p in sorted((root / c / split).glob("*.off"))]
    return ShapeDataset("modelnet", classes, split, items, cache_dir=cache_dir)
