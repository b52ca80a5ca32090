# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""Files written whole or not at all: every writer of the package goes through atomic_path.

A reader (another process, a run resumed after a crash) sees the old file or the whole new one,
never half of one: the new one is written to a temporary file in the same folder (a rename
across file systems would copy) and renamed onto its name once it is complete. A writer that
fails leaves the old file as it was and no temporary file behind.
"""
from __future__ import annotations

import itertools
import os
from contextlib import contextmanager
from pathlib import Path
from typing import IO, Iterator

_SERIAL = itertools.count()  # temporary names of one process never collide (threads included)


@contextmanager
def atomic_path(path) -> Iterator[Path]:
    """A temporary path beside `path` (its folder made if missing) for the caller to write;
    renamed onto `path` when the block ends, removed instead when it raises."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_name(f".{path.name}.{os.getpid()}.{next(_SERIAL)}.tmp")
    try:
        yield tmp
        os.replace(tmp, path)
    finally:
        tmp.unlink(missing_ok=True)


@contextmanager
def atomic_write(path, mode="w", **kwargs) -> Iterator[IO]:
    """open(path, mode) for writing ("w", "wb"; `kwargs` as open's), through atomic_path: the
    file is closed, then renamed into place."""
    if not mode.startswith("w"):
        raise ValueError(f"atomic_write {path}: mode {mode!r} does not write a new file")
    with atomic_path(path) as tmp, open(tmp, mode, **kwargs) as f:
        yield f


def write_text(path, text):
    """Write `text` to `path` atomically."""
    with atomic_write(path) as f:
        f.write(text)
