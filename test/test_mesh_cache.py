# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""The conversion cache of file datasets: each mesh file parsed once, changed files read again,
unusable files remembered with their reasons, entries written whole or not at all."""
import json
import os
import subprocess
import sys
import warnings
from pathlib import Path

import numpy as np
import pytest

from active_recognition.datasets import base, default_cache_dir, open_dataset
from active_recognition.sensing import meshes

ROOT = Path(__file__).resolve().parents[1]
TRI_V = [(0, 0, 0), (2, 0, 0), (0, 3, 0), (0, 0, 1)]
TRI_F = [(3, 0, 1, 2), (3, 0, 1, 3), (3, 0, 2, 3), (3, 1, 2, 3)]
CUBE_V = [(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0), (0, 0, 1), (1, 0, 1), (1, 1, 1), (0, 1, 1)]
CUBE_F = [(4, 0, 3, 2, 1), (4, 4, 5, 6, 7), (4, 0, 1, 5, 4), (4, 1, 2, 6, 5), (4, 2, 3, 7, 6),
          (4, 3, 0, 4, 7)]
BAD = {"chair/train/broken.off": ("OFF\n8 6 0\n1 2", "corrupt", "truncated or malformed OFF"),
       "chair/train/empty.off": ("", "empty", "file is empty"),
       "table/train/flat.off": ("OFF\n3 1 0\n0 0 0\n0 0 0\n0 0 0\n3 0 1 2\n", "degenerate",
                                "every face has zero area")}


def off_text(verts, faces, fused=False):
    head = f"OFF{len(verts)} {len(faces)} 0\n" if fused else f"OFF\n{len(verts)} {len(faces)} 0\n"
    return (head + "".join(f"{x} {y} {z}\n" for x, y, z in verts)
            + "".join(" ".join(map(str, f)) + "\n" for f in faces))


@pytest.fixture
def tree(tmp_path):
    """A ModelNet-style tree: 2 classes, 2 good train files each (one with ModelNet's fused
    header, one of quads), 1 test file each, and the three kinds of unusable file in train."""
    root = tmp_path / "ModelNet"
    for c, scale in (("chair", 1.0), ("table", 7.5)):
        for s in ("train", "test"):
            (root / c / s).mkdir(parents=True)
        (root / c / "train" / f"{c}_1.off").write_text(
            off_text(np.array(TRI_V) * scale + 100, TRI_F, fused=True))
        (root / c / "train" / f"{c}_2.off").write_text(off_text(CUBE_V, CUBE_F))
        (root / c / "test" / f"{c}_3.off").write_text(off_text(TRI_V, TRI_F, fused=True))
    for name, (text, _, _) in BAD.items():
        (root / name).write_text(text)
    return root


def count_loads(monkeypatch):
    """The files `load_mesh` parses from now on (a list that fills as they are read)."""
    seen, real = [], base.load_mesh

    def counting(path, **kwargs):
        seen.append(os.path.basename(path))
        return real(path, **kwargs)
    monkeypatch.setattr(base, "load_mesh", counting)
    return seen


def test_the_first_open_converts_and_a_second_parses_no_mesh_text(tree, tmp_path, monkeypatch):
    cache = tmp_path / "cache"
    first = open_dataset("modelnet", tree, "train", cache_dir=cache)
    assert len(first) == 4 and dict(first.loaded) == {"converted": 4}
    assert len(list((cache / "meshes").glob("*.npz"))) == 7  # 4 meshes, 3 remembered failures

    def refuse(*args):
        raise AssertionError("a cached mesh file was parsed again")
    monkeypatch.setattr(base, "load_mesh", refuse)
    monkeypatch.setattr(meshes, "parse_off", refuse)
    again = open_dataset("modelnet", tree, "train", cache_dir=cache)
    assert dict(again.loaded) == {"cache": 4} and again.items == first.items
    assert again.skipped == first.skipped and again.skip_counts() == first.skip_counts()
    for i in range(len(first)):
        for a, b in zip(again.mesh(i), first.mesh(i)):
            assert a.dtype == b.dtype and np.array_equal(a, b)


def test_unusable_files_are_skipped_and_counted_by_reason(tree, tmp_path, capsys):
    ds = open_dataset("modelnet", tree, "train", cache_dir=tmp_path / "cache")
    assert ds.skip_counts() == {"corrupt": 1, "empty": 1, "degenerate": 1}
    reasons = dict(ds.skipped)
    assert sorted(reasons) == sorted(str(tree / name) for name in BAD)
    for name, (_, _, reason) in BAD.items():
        assert reason in reasons[str(tree / name)]
    assert all(not p.name.startswith(("broken", "empty", "flat")) for p, _ in ds.items)
    err = capsys.readouterr().err
    assert ("modelnet/train: 4 meshes (4 converted, 0 from the cache" in err
            and "3 file(s) skipped (1 corrupt, 1 degenerate, 1 empty)" in err), err


def test_a_broken_link_gets_the_same_reason_with_the_cache_or_without(tree, tmp_path):
    """Before, the cache's key (the file's stat) raised first: 'unreadable' and errno text with
    the cache, 'no such file' without."""
    (tree / "chair" / "train" / "gone.off").symlink_to(tmp_path / "nowhere.off")
    with_cache = open_dataset("modelnet", tree, "train", cache_dir=tmp_path / "cache")
    without = open_dataset("modelnet", tree, "train", cache_dir=None)
    gone = str(tree / "chair" / "train" / "gone.off")
    assert dict(with_cache.skipped)[gone] == dict(without.skipped)[gone]
    assert "no such file" in dict(with_cache.skipped)[gone]
    assert with_cache.skip_counts() == without.skip_counts()
    assert len(list((tmp_path / "cache" / "meshes").glob("*.npz"))) == 7  # nothing kept for it


def test_a_changed_file_is_read_again_and_only_that_one(tree, tmp_path, monkeypatch):
    cache = tmp_path / "cache"
    open_dataset("modelnet", tree, "train", cache_dir=cache)
    seen = count_loads(monkeypatch)
    path = tree / "table" / "train" / "table_1.off"
    text = path.read_text().replace("\n0 ", "\n5 ", 1)  # one vertex moved, the size kept
    path.write_text(text)
    stat = path.stat()
    os.utime(path, ns=(stat.st_atime_ns, stat.st_mtime_ns + 10 ** 9))  # a clearly newer mtime
    again = open_dataset("modelnet", tree, "train", cache_dir=cache)
    assert seen == ["table_1.off"] and dict(again.loaded) == {"converted": 1, "cache": 3}
    i = next(i for i, (p, _) in enumerate(again.items) if p.name == "table_1.off")
    np.testing.assert_array_equal(again.mesh(i)[0], meshes.load_mesh(path)[0])
    # a broken file mended is read again too
    (tree / "chair" / "train" / "broken.off").write_text(off_text(TRI_V, TRI_F))
    mended = open_dataset("modelnet", tree, "train", cache_dir=cache)
    assert seen[1:] == ["broken.off"] and mended.skip_counts() == {"empty": 1, "degenerate": 1}


def test_a_cached_mesh_equals_the_directly_loaded_one(tree, tmp_path):
    ds = open_dataset("modelnet", tree, "train", cache_dir=tmp_path / "cache")
    again = open_dataset("modelnet", tree, "train", cache_dir=tmp_path / "cache")
    assert dict(again.loaded) == {"cache": 4}
    for i, (path, _) in enumerate(ds.items):
        direct = meshes.load_mesh(path)
        for cached, loaded in zip(again.mesh(i), direct):
            assert cached.dtype == loaded.dtype and np.array_equal(cached, loaded)
        assert direct[0].dtype == np.float32 and direct[1].dtype == np.int32
    chair = again.mesh(0)[0]  # the fused-header tetrahedron, moved and normalised
    np.testing.assert_allclose(chair.max(0) - chair.min(0), [2 / 3, 1, 1 / 3], atol=1e-6)


def test_an_interrupted_write_leaves_no_file_and_a_damaged_entry_is_rebuilt(tree, tmp_path,
                                                                            monkeypatch):
    cache = tmp_path / "cache"
    real = np.savez

    def dies_midway(f, **arrays):
        f.write(b"PK\x03\x04 half a zip")
        raise KeyboardInterrupt  # the user's Ctrl-C in the middle of a write
    monkeypatch.setattr(base.np, "savez", dies_midway)
    with pytest.raises(KeyboardInterrupt):
        open_dataset("modelnet", tree, "train", cache_dir=cache)
    assert list((cache / "meshes").iterdir()) == []  # neither the entry nor a temporary file
    monkeypatch.setattr(base.np, "savez", real)
    ds = open_dataset("modelnet", tree, "train", cache_dir=cache)
    entries = sorted((cache / "meshes").iterdir())
    assert len(entries) == 7 and all(p.suffix == ".npz" for p in entries)
    for p in entries:  # every entry damaged, as by a full disk: all are converted again
        p.write_bytes(p.read_bytes()[:40])
    seen = count_loads(monkeypatch)
    again = open_dataset("modelnet", tree, "train", cache_dir=cache)
    assert len(seen) == 7 and dict(again.loaded) == {"converted": 4}
    assert again.skip_counts() == ds.skip_counts()
    for i in range(len(ds)):
        np.testing.assert_array_equal(again.mesh(i)[1], ds.mesh(i)[1])


def test_the_cache_folder_follows_the_environment(monkeypatch, tmp_path):
    monkeypatch.delenv("ACTIVE_RECOGNITION_CACHE", raising=False)
    monkeypatch.delenv("XDG_CACHE_HOME", raising=False)
    monkeypatch.setenv("HOME", str(tmp_path / "home"))
    assert default_cache_dir() == tmp_path / "home" / ".cache" / "active_recognition"
    monkeypatch.setenv("XDG_CACHE_HOME", "relative/ignored")  # the XDG spec: absolute only
    assert default_cache_dir() == tmp_path / "home" / ".cache" / "active_recognition"
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "xdg"))
    assert default_cache_dir() == tmp_path / "xdg" / "active_recognition"
    monkeypatch.setenv("ACTIVE_RECOGNITION_CACHE", str(tmp_path / "mine"))
    assert default_cache_dir() == tmp_path / "mine"


def test_the_triangle_block_and_the_polygon_walk_parse_alike():
    rng = np.random.default_rng(5)
    verts = rng.normal(size=(50, 3))
    tris = rng.integers(0, 50, size=(80, 3))
    text = off_text(verts, [(3, *t) for t in tris], fused=True)
    v, f = meshes.parse_off(text + "trailing words after the faces\n")  # block path
    np.testing.assert_array_equal(v, np.array(text.split()[3:153], dtype=float).reshape(50, 3))
    np.testing.assert_array_equal(f, tris)
    polys = [(3, *tris[0]), (5, 1, 2, 3, 4, 5), (4, 6, 7, 8, 9), (3, *tris[1])]
    _, f = meshes.parse_off(off_text(verts, polys))  # walk path: fans, in the file's order
    np.testing.assert_array_equal(f, [tris[0], (1, 2, 3), (1, 3, 4), (1, 4, 5), (6, 7, 8),
                                      (6, 8, 9), tris[1]])
    with pytest.raises(ValueError, match="face with 3 corners"):  # the last one cut short
        meshes.parse_off(off_text(verts, polys)[:-1].rsplit(" ", 2)[0])


@pytest.mark.slow
def test_the_load_benchmark_counts_the_whole_training_split_and_the_scenes_training_builds(tmp_path):
    """benchmarks/dataset_generation.py on a small ModelNet tree: every file of the training split
    (train and val, read once) and of test, the bad one skipped, and a scene per training shape
    less the validation ones."""
    from test_datasets import CUBE_QUADS, CUBE_V, write_off
    for c in ("bed", "chair"):
        for split, n in (("train", 10), ("test", 2)):
            (tmp_path / c / split).mkdir(parents=True)
            for i in range(n):
                write_off(tmp_path / c / split / f"{c}_{i:04d}.off", np.array(CUBE_V) * (1 + i), CUBE_QUADS)
    (tmp_path / "bed" / "train" / "bed_0099.off").write_text("OFF\n3 1 0\n0 0 0\n")  # truncated
    out = subprocess.run([sys.executable, str(ROOT / "benchmarks" / "dataset_generation.py"), "--dataset",
                          "modelnet", "--root", str(tmp_path), "--size", "16"],
                         capture_output=True, text=True, check=True)
    fig = json.loads(out.stdout.strip().splitlines()[-1])
    assert (fig["train"]["files"], fig["train"]["loaded"], fig["train"]["skipped_files"]) == \
        (21, 20, [str(tmp_path / "bed" / "train" / "bed_0099.off")])
    assert (fig["test"]["files"], fig["test"]["loaded"]) == (4, 4)
    assert fig["scenes"] == 18  # a tenth of each class's 10 is held out for validation
    assert fig["warm_converted"] == 0 and fig["warm_from_cache"] == 24


def test_the_docs_give_the_committed_modelnet10_load_figures():
    """docs/datasets.md's load times and memory are those of docs/results/modelnet10/loading.json."""
    fig = json.loads((ROOT / "docs" / "results" / "modelnet10" / "loading.json").read_text())
    readme = " ".join((ROOT / "docs" / "datasets.md").read_text().split())
    files = fig["train"]["files"] + fig["test"]["files"]
    skipped = sum(sum(fig[s]["skipped"].values()) for s in ("train", "test"))
    expected = [f"all {files:,} files load" if not skipped else f"{skipped} skipped",
                f"{fig['cold_s']:.1f} s the first time ({fig['cold_cpu_s']:.1f} s of CPU",
                f"{fig['cache_mb']:.0f} MiB cache), {fig['warm_s']:.1f} s from the cache",
                f"({fig['rss_meshes_mb']:.0f} MiB resident",
                f"({fig['rss_train_scenes_mb']:.0f} MiB more for the {fig['scenes']:,} "
                f"scenes, built in {fig['scenes_build_s']:.0f} s)"]
    for text in expected:
        assert text in readme, text


@pytest.mark.parametrize("scale", [1e300, 1e-200])
def test_huge_and_tiny_coordinates_normalise_like_any_others_without_warnings(scale):
    """A file drawn in absurd units is the same shape: its face areas are taken in units of its
    largest coordinate, so they neither overflow (a RuntimeWarning, before) nor underflow (every
    face 'zero area', before)."""
    verts = np.array(TRI_V, dtype=np.float64) + 1
    faces = np.array([f[1:] for f in TRI_F])
    want_v, want_f = meshes.check_mesh("unit.off", verts, faces)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        got_v, got_f = meshes.check_mesh("scaled.off", verts * scale, faces)
    np.testing.assert_allclose(got_v, want_v, atol=1e-6)
    np.testing.assert_array_equal(got_f, want_f)
