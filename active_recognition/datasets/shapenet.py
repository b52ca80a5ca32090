# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""ShapeNetCore v2: root/<synset>/<model>/models/model_normalized.obj, deterministic 80/20 split."""
from __future__ import annotations

import json

from active_recognition.argument_checks import InputError
from active_recognition.datasets.base import ShapeDataset, check_root, check_split, in_split


def synset_names(root):
    """synset id -> first name from taxonomy.json, where present."""
    path = root / "taxonomy.json"
    if not path.is_file():
        return {}
    try:
        entries = json.loads(path.read_text())
        return {e["synsetId"]: e["name"].split(",")[0].strip() for e in entries}
    except (ValueError, KeyError, TypeError) as e:
        raise InputError(f"{path}: not a ShapeNet taxonomy ({e})") from None


def shapenet(root, split="train", cache_dir=None, test_fraction=0.2):
    check_split(split)
    root = check_root(root, "shapenet")
    names = synset_names(root)
    synsets = sorted(p.name for p in root.iterdir() if p.is_dir())
    items, classes = [], []
    for synset in synsets:
        models = sorted((root / synset).glob("*/models/model_normalized.obj"))
        if not models:
            continue
        label = len(classes)
        classes.append(names.get(synset, synset))
        for m in models:
            if in_split(f"{synset}/{m.parent.parent.name}", split, test_fraction):
                items.append((m, label))
    if not classes:
        raise InputError(f"shapenet root {root} has no <synset>/<model>/models/model_normalized.obj")
    return ShapeDataset("shapenet", classes, split, items, cache_dir=cache_dir,
                        layout=f"shapenet root {root}")
