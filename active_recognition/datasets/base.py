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

"""What every dataset is: a list of (source, label) per split, meshes loaded once and cached."""
from __future__ import annotations

import hashlib
import os
import sys
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..meshes import MeshError, load_mesh
from ..validation import InputError

SPLITS = ("train", "test")


def default_cache_dir():
    return Path(os.environ.get("ACTIVE_RECOGNITION_CACHE",
                               Path.home() / ".cache" / "active_recognition"))


def stable_fraction(key: str) -> float:
    """A deterministic number in [0, 1) from a string (for splits that must not change)."""
    return int(hashlib.sha1(key.encode()).hexdigest()[:8], 16) / 2 ** 32


def in_split(key: str, split: str, test_fraction: float) -> bool:
    """Whether the item named `key` belongs to `split` under a stable hash split."""
    return (stable_fraction(key) < test_fraction) == (split == "test")


def save_npz_atomic(path: Path, **arrays):
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_name(f".{path.name}.{os.getpid()}.tmp")
    with open(tmp, "wb") as f:
        np.savez(f, **arrays)
    os.replace(tmp, path)


def load_npz(path: Path, keys):
    """The arrays `keys` of a cache file, or None when it is missing or unreadable (a cache
    written half or damaged is rebuilt, never trusted)."""
    if not path.is_file():
        return None
    try:
        with np.load(path) as z:
            return tuple(np.array(z[k]) for k in keys)
    except Exception:  # truncated zip, bad header, missing key: all mean "rebuild it"
        return None


@dataclass
class ShapeDataset:
    """Shapes of one split. `items` are (source, label); `mesh(i)` gives normalised arrays."""

    name: str
    classes: list
    split: str
    items: list
    skipped: list = field(default_factory=list)  # (source, reason), each reported once
    cache_dir: Path | None = None
    _meshes: dict = field(default_factory=dict, repr=False)
    layout: str = ""  # where the items were looked for, e.g. "modelnet root R (R/<class>/train/*.off)"

    def __post_init__(self):
        self.cache_dir = None if self.cache_dir is None else Path(self.cache_dir)

    def __len__(self):
        return len(self.items)

    def labels(self):
        return np.array([label for _, label in self.items], dtype=np.int64)

    def class_counts(self):
        return np.bincount(self.labels(), minlength=len(self.classes))

    def require_objects(self, which=None):
        """self, or InputError when the split holds no usable object (`which`: what to call the
        objects in the message; default "<split> objects")."""
        if not len(self):
            bad = f" ({len(self.skipped)} file(s) found, all unusable)" if self.skipped else ""
            raise InputError(f"no {which or self.split + ' objects'} found in "
                             f"{self.layout or self.name}{bad}")
        return self

    def mesh(self, i):
        """(vertices (V, 3) float32 in [-0.5, 0.5]^3, faces (F, 3) int32) of item i."""
        if i not in self._meshes:
            self._meshes[i] = self._load(self.items[i][0])
        return self._meshes[i]

    def _load(self, source):
        path = Path(source)
        if self.cache_dir is None:
            return load_mesh(path)
        stat = path.stat()
        key = hashlib.sha1(f"{path.resolve()}|{stat.st_size}|{stat.st_mtime_ns}".encode())
        cached = self.cache_dir / "meshes" / f"{key.hexdigest()}.npz"
        arrays = load_npz(cached, ("vertices", "faces"))
        if arrays is not None:
            return arrays
        verts, faces = load_mesh(path)
        save_npz_atomic(cached, vertices=verts, faces=faces)
        return verts, faces

    def validate(self, progress=True):
        """Load every mesh once; drop and record the unusable ones. Returns self."""
        try:
            from tqdm import tqdm
            it = tqdm(range(len(self.items)), desc=f"{self.name}/{self.split}", disable=not progress,
                      file=sys.stderr)
        except ImportError:  # pragma: no cover
            it = range(len(self.items))
        good = []
        for i in it:
            try:
                self.mesh(i)
                good.append(i)
            except (MeshError, OSError) as e:
                self.skipped.append((str(self.items[i][0]), getattr(e, "reason", str(e))))
        self.keep(good)
        return self

    def keep(self, indices):
        """Keep only the items at `indices` (in that order), with their loaded meshes."""
        indices = [int(i) for i in indices]
        self._meshes = {new: self._meshes[old] for new, old in enumerate(indices)
                        if old in self._meshes}
        self.items = [self.items[i] for i in indices]
        return self


def check_split(split):
    if split not in SPLITS:
        raise InputError(f"split must be one of {', '.join(SPLITS)}, got {split!r}")


def check_root(root, layout):
    if root is None or str(root) == "":
        raise InputError(f"the {layout} dataset needs its root folder (--root DIR)")
    root = Path(root)
    if not root.is_dir():
        raise InputError(f"{layout} dataset root {root}: "
                         f"{'is not a directory' if root.exists() else 'no such directory'}")
    return root
