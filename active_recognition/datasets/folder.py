# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""A plain folder: root/<class>/*.<ext> for any mesh format, deterministic split."""
from __future__ import annotations

from active_recognition.argument_checks import InputError
from active_recognition.datasets.base import ShapeDataset, check_root, check_split, in_split
from active_recognition.sensing.meshes import SUFFIXES


def folder(root, split="train", cache_dir=None, test_fraction=0.2):
    check_split(split)
    root = check_root(root, "folder")
    classes = sorted(p.name for p in root.iterdir() if p.is_dir())
    items = []
    for label, c in enumerate(classes):
        for p in sorted((root / c).iterdir()):
            if p.suffix.lower() in SUFFIXES:
                if in_split(f"{c}/{p.name}", split, test_fraction):
                    items.append((p, label))
    if not classes:
        raise InputError(f"folder root {root} has no class folders")
    hint = ("; its <class>/train/ folders look like modelnet's: --name modelnet?"
            if any((root / c / s).is_dir() for c in classes for s in ("train", "test")) else "")
    layout = f"folder root {root} ({root}/<class>/*{{{','.join(SUFFIXES)}}}{hint})"
    return ShapeDataset("folder", classes, split, items, cache_dir=cache_dir, layout=layout)
