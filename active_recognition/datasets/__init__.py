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

"""Shape datasets: ModelNet, ShapeNetCore, a plain folder, and the embedded benchmarks
(procedural, twins)."""
from __future__ import annotations

from .base import ShapeDataset, default_cache_dir
from .folder import folder
from .modelnet import modelnet
from .procedural import procedural
from .shapenet import shapenet
from .twins import twins
from ..validation import InputError

NAMES = ("procedural", "twins", "modelnet", "shapenet", "folder")
GENERATED = {"procedural": procedural, "twins": twins}


def open_dataset(name, root=None, split="train", cache_dir=None, validate=True, **kwargs):
    """Open a split of a dataset by name; file datasets are validated (bad files skipped)."""
    if name in GENERATED:
        if root:
            raise InputError(f"the {name} dataset is generated: it takes no root folder "
                             f"(got {root}); roots are for modelnet, shapenet and folder")
        return GENERATED[name](split, cache_dir=cache_dir, **kwargs)
    loaders = {"modelnet": modelnet, "shapenet": shapenet, "folder": folder}
    if name not in loaders:
        raise InputError(f"dataset must be one of {', '.join(NAMES)}, got {name!r}")
    ds = loaders[name](root, split, cache_dir=cache_dir, **kwargs)
    return ds.validate() if validate else ds


def describe(name, root=None, cache_dir=None):
    """Print a dataset's class counts per split and its skipped files (with why); warn of a class
    a split lacks. -> {split: dataset}. InputError, saying what was looked for, when empty."""
    import sys

    splits = {s: open_dataset(name, root, s, cache_dir=cache_dir) for s in ("train", "test")}
    classes = splits["train"].classes
    width = max(len(c) for c in classes + ["class"])
    print(f"{name}: {len(classes)} classes")
    print(f"{'class':<{width}}  {'train':>6}  {'test':>6}")
    counts = {s: ds.class_counts() for s, ds in splits.items()}
    for i, c in enumerate(classes):
        print(f"{c:<{width}}  {counts['train'][i]:>6}  {counts['test'][i]:>6}")
    print(f"{'total':<{width}}  {len(splits['train']):>6}  {len(splits['test']):>6}")
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


__all__ = ["ShapeDataset", "open_dataset", "default_cache_dir", "describe", "NAMES"]
