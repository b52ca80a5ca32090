# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""What every dataset is: a list of (source, label) per split, meshes loaded once and cached.

The conversion cache of file datasets (ModelNet, ShapeNet, a folder): each mesh file is parsed and
normalised once (`load_mesh`) and kept as float32 vertices, int32 faces and the longest edge of
its box before normalising (the object's size in the file's units) in one .npz per file,
`<cache_dir>/meshes/<key>.npz`, the key a hash of the cache version, the file's resolved path, its
size and its modification time, so a changed file is read again. A file that cannot be used is
cached too, as its reason, so a later run parses no mesh text at all. Writes go to a temporary
file renamed into place: an interrupted run leaves whole entries or none.
"""
from __future__ import annotations

import hashlib
import os
import sys
from collections import Counter
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from active_recognition.argument_checks import InputError
from active_recognition.atomic_files import atomic_write
from active_recognition.sensing.meshes import MeshError, load_mesh

SPLITS = ("train", "test")
MESH_CACHE_VERSION = 2  # bump when load_mesh gives other arrays for the same file (2: the edge)


def default_cache_dir():
    """$ACTIVE_RECOGNITION_CACHE, else $XDG_CACHE_HOME/active_recognition, else
    ~/.cache/active_recognition."""
    if os.environ.get("ACTIVE_RECOGNITION_CACHE"):
        return Path(os.environ["ACTIVE_RECOGNITION_CACHE"])
    xdg = os.environ.get("XDG_CACHE_HOME")
    base = Path(xdg) if xdg and Path(xdg).is_absolute() else Path.home() / ".cache"
    return base / "active_recognition"


def stable_fraction(key: str) -> float:
    """A deterministic number in [0, 1) from a string (for splits that must not change)."""
    return int(hashlib.sha1(key.encode()).hexdigest()[:8], 16) / 2 ** 32


def in_split(key: str, split: str, test_fraction: float) -> bool:
    """Whether the item named `key` belongs to `split` under a stable hash split."""
    return (stable_fraction(key) < test_fraction) == (split == "test")


def save_npz_atomic(path: Path, **arrays):
    """Write `arrays` to `path` atomically (files.atomic_write): readers see the old file or
    the whole new one."""
    with atomic_write(path, "wb") as f:
        np.savez(f, **arrays)


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


def mesh_cache_path(cache_dir: Path, path: Path) -> Path:
    """The conversion cache's entry for mesh file `path` as it is now (path, size, mtime)."""
    stat = path.stat()
    key = f"v{MESH_CACHE_VERSION}|{path.resolve()}|{stat.st_size}|{stat.st_mtime_ns}"
    return Path(cache_dir) / "meshes" / f"{hashlib.sha1(key.encode()).hexdigest()}.npz"


def load_mesh_entry(entry: Path, source):
    """A conversion-cache entry: (vertices, faces, edge), a MeshError for a file cached as unusable,
    or None when the entry is missing or damaged (then the file is converted again)."""
    if not entry.is_file():
        return None
    try:
        with np.load(entry) as z:
            if "reason" in z.files:
                kind = str(z["kind"])
                if kind not in MeshError.KINDS:
                    return None
                return MeshError(source, str(z["reason"]), kind)
            return np.array(z["vertices"]), np.array(z["faces"]), float(z["edge"])
    except Exception:  # truncated zip, bad header, missing key: all mean "convert it again"
        return None


def convert_mesh(source, cache_dir=None):
    """(vertices (V, 3) float32, faces (F, 3) int32, the box's longest edge in the file's units,
    whether it came from the cache) of the mesh file `source`, normalised by `load_mesh`; through
    the conversion cache under
    `cache_dir` when given. Raises MeshError (from the cache too) for an unusable file,
    OSError when it cannot be read."""
    path = Path(source)
    if cache_dir is None or not path.is_file():  # nothing to key an entry on (a broken link): the
        return (*load_mesh(path, edge=True), False)  # reason is load_mesh's, cache or not
    entry = mesh_cache_path(cache_dir, path)
    cached = load_mesh_entry(entry, path)
    if isinstance(cached, MeshError):
        raise cached
    if cached is not None:
        return (*cached, True)
    try:
        verts, faces, edge = load_mesh(path, edge=True)
    except MeshError as e:  # remembered, so a later run does not parse it again
        save_npz_atomic(entry, reason=np.array(e.reason), kind=np.array(e.kind))
        raise
    save_npz_atomic(entry, vertices=verts, faces=faces, edge=np.array(edge))
    return verts, faces, edge, False


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
    loaded: Counter = field(default_factory=Counter)  # meshes "converted" / read from "cache"
    _skip_kinds: dict = field(default_factory=dict, repr=False)  # source -> MeshError kind
    # metres per unit of the files (ModelNet: inches), for the objects' sizes; None: unknown
    unit: float | None = None
    _edges: dict = field(default_factory=dict, repr=False)  # source -> longest box edge, file units

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
        verts, faces, edge, cached = convert_mesh(source, self.cache_dir)
        self.loaded["cache" if cached else "converted"] += 1
        self._edges[source] = edge
        return verts, faces

    def size(self, i):
        """Item i's size, the longest edge of its box in metres; None where the files' unit is
        unknown or the item is generated."""
        if self.unit is None:
            return None
        self.mesh(i)
        edge = self._edges.get(self.items[i][0])
        return None if edge is None else edge * self.unit

    def validate(self, progress=True):
        """Load every mesh once (converted, or from the cache); drop and record the unusable
        ones with their reasons. With `progress`, a progress bar and then `summary()` on
        stderr. Returns self."""
        try:
            from tqdm import tqdm
            it = tqdm(range(len(self.items)), desc=f"{self.name}/{self.split}", disable=not progress,
                      file=sys.stderr, unit="mesh")
        except ImportError:  # pragma: no cover
            it = range(len(self.items))
        good = []
        for i in it:
            try:
                self.mesh(i)
                good.append(i)
            except (MeshError, OSError) as e:
                source = str(self.items[i][0])
                self.skipped.append((source, getattr(e, "reason", None) or str(e)))
                self._skip_kinds[source] = getattr(e, "kind", "unreadable")
        self.keep(good)
        if progress and (self.loaded or self.skipped):
            print(self.summary(), file=sys.stderr)
        return self

    def skip_counts(self):
        """{reason kind: files} of the skipped files: 'corrupt', 'empty', 'degenerate' (see
        MeshError) or 'unreadable' (the system could not read the file)."""
        return dict(Counter(self._skip_kinds.get(source, "corrupt") for source, _ in self.skipped))

    def summary(self):
        """One line: meshes kept, how many were converted and how many read from the cache,
        and the files skipped by kind of reason."""
        kinds = ", ".join(f"{n} {kind}" for kind, n in sorted(self.skip_counts().items()))
        return (f"{self.name}/{self.split}: {len(self)} meshes ({self.loaded['converted']} "
                f"converted, {self.loaded['cache']} from the cache"
                f"{f' {self.cache_dir}' if self.cache_dir else ''}), {len(self.skipped)} "
                f"file(s) skipped{f' ({kinds})' if kinds else ''}")

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
        raise InputError(f"the {layout} dataset needs its root folder (--root DIR; a node's parameter root)")
    root = Path(root)
    if not root.is_dir():
        raise InputError(f"{layout} dataset root {root}: "
                         f"{'is not a directory' if root.exists() else 'no such directory'}")
    return root
