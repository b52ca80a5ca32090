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

"""A plain folder: root/<class>/*.<ext> for any mesh format, deterministic split."""
from __future__ import annotations

from .base import ShapeDataset, check_root, check_split, in_split
from ..meshes import SUFFIXES
from ..validation import InputError


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
