# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""Atomic writes (atomic_files.py): a writer that fails leaves the old file and no temporary file."""
import threading
from pathlib import Path

import numpy as np
import pytest
import torch

from active_recognition.atomic_files import atomic_path, atomic_write, write_text
from active_recognition.datasets.base import save_npz_atomic
from active_recognition.model import checkpoint
from active_recognition.training.run_metrics import write_metrics


class Unpicklable:
    def __reduce__(self):
        raise RuntimeError("cannot be written")


class Unprintable:
    def __str__(self):
        raise RuntimeError("cannot be written")


def test_a_write_replaces_the_file_whole_with_a_plain_files_permissions(tmp_path):
    plain = tmp_path / "plain.txt"
    plain.write_text("x")
    write_text(tmp_path / "sub" / "out.txt", "old")  # the folder is made
    write_text(tmp_path / "sub" / "out.txt", "new")
    assert (tmp_path / "sub" / "out.txt").read_text() == "new"
    assert [p.name for p in (tmp_path / "sub").iterdir()] == ["out.txt"]
    assert (tmp_path / "sub" / "out.txt").stat().st_mode == plain.stat().st_mode


def test_a_writer_that_fails_mid_write_leaves_the_old_file_and_no_temporary_one(tmp_path):
    path = tmp_path / "out.bin"
    path.write_bytes(b"old")
    with pytest.raises(RuntimeError, match="half"):
        with atomic_write(path, "wb") as f:
            f.write(b"new, but only")
            f.flush()
            assert path.read_bytes() == b"old"  # readers see the old file meanwhile
            raise RuntimeError("half written")
    assert path.read_bytes() == b"old"
    assert [p.name for p in tmp_path.iterdir()] == ["out.bin"]


def test_a_figure_is_written_through_a_temporary_path(tmp_path):
    with atomic_path(tmp_path / "plot.png") as tmp:
        assert tmp.parent == tmp_path and tmp.name.endswith(".tmp") and not tmp.exists()
        tmp.write_bytes(b"png")
    assert [p.name for p in tmp_path.iterdir()] == ["plot.png"]


def test_atomic_write_refuses_a_mode_that_does_not_write_a_new_file(tmp_path):
    with pytest.raises(ValueError, match="mode 'a'"):
        with atomic_write(tmp_path / "log.txt", "a"):
            pass


def test_threads_writing_one_file_never_share_a_temporary_name(tmp_path):
    path, errors = tmp_path / "shared.txt", []

    def write(i):
        try:
            for _ in range(20):
                write_text(path, f"{i}" * 1000)
        except Exception as e:  # a collision would rename a file another thread removed
            errors.append(e)

    threads = [threading.Thread(target=write, args=(i,)) for i in range(4)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert errors == [] and len(set(path.read_text())) == 1
    assert [p.name for p in tmp_path.iterdir()] == ["shared.txt"]


@pytest.mark.parametrize("writer", ["checkpoint", "npz", "metrics"])
def test_the_packages_writers_keep_the_old_file_when_they_fail_mid_write(tmp_path, writer):
    path = tmp_path / {"checkpoint": "model.pt", "npz": "cache.npz", "metrics": "metrics.csv"}[writer]
    if writer == "checkpoint":
        checkpoint.save(path, {"model": {"w": torch.ones(2)}})
        before = path.read_bytes()
        with pytest.raises(RuntimeError, match="cannot be written"):
            checkpoint.save(path, {"model": {"w": torch.zeros(2)}, "bad": Unpicklable()})
    elif writer == "npz":
        save_npz_atomic(path, a=np.ones(3))
        before = path.read_bytes()
        with pytest.raises(RuntimeError, match="cannot be written"):
            save_npz_atomic(path, a=np.zeros(3), b=np.array([Unpicklable()], dtype=object))
    else:
        write_metrics(path, [{"epoch": 1, "loss": 0.5}])
        before = path.read_bytes()
        with pytest.raises(RuntimeError, match="cannot be written"):
            write_metrics(path, [{"epoch": 1, "loss": 0.4}, {"epoch": 2, "loss": Unprintable()}])
    assert path.read_bytes() == before
    assert [p.name for p in tmp_path.iterdir()] == [path.name]


def test_a_checkpoint_updated_keeps_all_else_and_writes_where_asked(tmp_path):
    """checkpoint.update: the fields given replace theirs, every other key and tensor is kept, and
    with `out` the source is left as it was."""
    src, dst = tmp_path / "a.pt", tmp_path / "b.pt"
    src.write_bytes(Path(checkpoint.shipped("procedural")).read_bytes())
    checkpoint.update(src, dst, default_planner="random", fixed_path=[[0.1, 0.2]])
    before, after = checkpoint.read(src), checkpoint.read(dst)
    assert before["default_planner"] != "random" and before.get("fixed_path") != [[0.1, 0.2]]
    assert after["default_planner"] == "random" and after["fixed_path"] == [[0.1, 0.2]]
    assert set(after) == set(before)
    assert all(torch.equal(v, after["model"][k]) for k, v in before["model"].items())
    assert all(after[k] == before[k] for k in set(before) - {"model", "default_planner", "fixed_path"})
    checkpoint.update(src, default_planner="straight")
    assert checkpoint.read(src)["default_planner"] == "straight"
