# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""The real unknowns: the shipped manifest is well formed and keeps its splits apart, and the
tool rebuilds an object from a tiny git repository made here (no network, no real meshes) into a
PLY in metres that real_unknowns opens, refusing a file whose git blob hash is not the manifest's."""
import importlib.util
import re
import subprocess
from collections import defaultdict
from pathlib import Path

import numpy as np
import pytest
import trimesh

from active_recognition.argument_checks import InputError
from active_recognition.datasets import open_dataset
from active_recognition.datasets.real_unknowns import (COLUMNS, MANIFEST, near, near_classes, ply_path,
                                                       read_manifest, real_unknowns)

TOOL = Path(__file__).resolve().parents[1] / "tools" / "fetch_real_unknowns.py"
MODELNET10 = {"bathtub", "bed", "chair", "desk", "dresser", "monitor", "night_stand", "sofa", "table", "toilet",
              "tv", "television", "screen", "drawers", "chest"}
HEX40 = re.compile(r"[0-9a-f]{40}")


def load_tool():
    spec = importlib.util.spec_from_file_location("fetch_real_unknowns", TOOL)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_the_shipped_manifest_is_well_formed_and_its_splits_apart():
    rows = read_manifest()  # the header is COLUMNS, numbers parse, split/unit/near in range
    assert MANIFEST.read_text().startswith("#") and rows
    assert {r["split"] for r in rows} == {"train", "val", "test"}
    for r in rows:
        assert HEX40.fullmatch(r["commit"]) and HEX40.fullmatch(r["blob"]) and r["bytes"] > 0, r
        assert r["unit"] > 0 and r["near"] in (0, 1) and "/" in r["repo"], r
        assert r["class"] not in MODELNET10, r
    repos, blobs, objects = defaultdict(set), defaultdict(set), defaultdict(set)
    for r in rows:
        repos[r["split"]].add(r["repo"])
        blobs[r["split"]].add(r["blob"])
        objects[ply_path(r)].add((r["repo"], r["object"], r["class"], r["near"]))
    for a, b in (("val", "test"), ("train", "val"), ("train", "test")):
        assert not repos[a] & repos[b] and not blobs[a] & blobs[b], (a, b)
    assert all(len(v) == 1 for v in objects.values())  # one object per output file, one class and near each
    near_of = defaultdict(set)
    for r in rows:
        near_of[r["class"]].add(r["near"])
    assert all(len(v) == 1 for v in near_of.values())  # near() reads it by class: one value a class
    assert len([r["blob"] for r in rows]) == len({r["blob"] for r in rows})  # no file twice
    assert {"bookshelf", "wardrobe", "bench"} <= near_classes() and "cup" not in near_classes()


@pytest.fixture
def tiny(tmp_path):
    """A bare mirror <tmp>/mirrors/someone+tiny/repo of a repository with two box meshes (.stl and
    .obj, in centimetres) and a manifest making them one object of class `widget`, unit 0.01."""
    work = tmp_path / "work"
    (work / "meshes").mkdir(parents=True)
    trimesh.creation.box(extents=(10, 20, 30)).export(work / "meshes" / "body.stl")
    trimesh.creation.box(extents=(5, 5, 5)).apply_translation((0, 0, 20)).export(work / "meshes" / "lid.obj")
    git = ["git", "-c", "user.name=t", "-c", "user.email=t@t", "-c", "init.defaultBranch=main"]
    subprocess.run(git + ["init", "-q", str(work)], check=True)
    subprocess.run(git + ["-C", str(work), "add", "meshes"], check=True)
    subprocess.run(git + ["-C", str(work), "commit", "-q", "-m", "meshes"], check=True)
    mirror = tmp_path / "mirrors" / "someone+tiny" / "repo"
    subprocess.run(git + ["clone", "-q", "--bare", str(work), str(mirror)], check=True)

    def rev(what):
        return subprocess.run(["git", "-C", str(work), "rev-parse", what], capture_output=True, text=True,
                              check=True).stdout.strip()

    commit = rev("HEAD")
    rows = [("test", "someone/tiny", commit, f"meshes/{f}", rev(f"HEAD:meshes/{f}"),
             str((work / "meshes" / f).stat().st_size), "widget", "thing", "0.01", "0")
            for f in ("body.stl", "lid.obj")]
    manifest = tmp_path / "manifest.tsv"
    manifest.write_text("# a test manifest\n" + "\n".join("\t".join(r) for r in [COLUMNS] + rows) + "\n")
    return dict(manifest=manifest, mirrors=tmp_path / "mirrors", out=tmp_path / "out", work=work)


def run(tool, tiny, *extra):
    return tool.main(["--out", str(tiny["out"]), "--manifest", str(tiny["manifest"]), *extra])


def test_the_tool_rebuilds_one_merged_object_in_metres_and_skips_it_again(tiny, capsys, tmp_path):
    tool = load_tool()
    assert run(tool, tiny, "--mirrors", str(tiny["mirrors"])) == 0
    ply = tiny["out"] / "test" / "widget" / "tiny__thing.ply"
    assert [p.name for p in tiny["out"].rglob("*") if p.is_file()] == [ply.name]
    mesh = trimesh.load(ply)
    assert len(mesh.faces) == 24  # both boxes
    np.testing.assert_allclose(mesh.extents, [0.10, 0.20, 0.375], atol=1e-6)  # z: -15 .. 22.5 cm

    ds = real_unknowns(tiny["out"], "test", cache_dir=tmp_path / "cache")
    assert ds.classes == ["widget"] and len(ds) == 1 and ds.unit == 1.0
    assert ds.size(0) == pytest.approx(0.375, abs=1e-6) and not near(ds, 0)
    opened = open_dataset("real_unknowns", tiny["out"], "test", cache_dir=tmp_path / "cache")
    assert len(opened) == 1 and opened.size(0) == pytest.approx(0.375, abs=1e-6)

    before = ply.stat().st_mtime_ns
    capsys.readouterr()
    assert run(tool, tiny, "--mirrors", str(tiny["mirrors"])) == 0
    assert ply.stat().st_mtime_ns == before
    assert re.search(r"test\s+widget\s+0\s+1\s+0", capsys.readouterr().out)


def test_a_mirror_that_is_a_clone_serves_as_a_bare_one(tiny, tmp_path, monkeypatch):
    """fetch may leave a clone (repo/.git) where a bare mirror is expected: its objects are read, nothing
    downloaded."""
    clones = tmp_path / "clones"
    subprocess.run(["git", "clone", "-q", str(tiny["work"]), str(clones / "someone+tiny" / "repo")], check=True)
    tool = load_tool()

    def offline(*a, **k):
        raise AssertionError("downloaded although a mirror was there")

    monkeypatch.setattr(tool.urllib.request, "urlopen", offline)
    assert run(tool, tiny, "--mirrors", str(clones)) == 0
    assert len(trimesh.load(tiny["out"] / "test" / "widget" / "tiny__thing.ply").faces) == 24


def test_a_file_whose_blob_hash_differs_is_refused_and_nothing_written(tiny, capsys, monkeypatch):
    """No mirror: the files are 'downloaded' (urlopen replaced by the work tree's files); the
    manifest's hash of lid.obj is wrong, so the object is refused, naming the file."""
    text = tiny["manifest"].read_text()
    blob = re.search(r"meshes/lid\.obj\t([0-9a-f]{40})", text).group(1)
    tiny["manifest"].write_text(text.replace(blob, "0" * 40))
    tool = load_tool()
    urls = []

    class Response:
        def __init__(self, url):
            urls.append(url)
            self.data = (tiny["work"] / url.split("/", 6)[-1]).read_bytes()

        def read(self):
            return self.data

        def __enter__(self):
            return self

        def __exit__(self, *exc):
            return False

    monkeypatch.setattr(tool.urllib.request, "urlopen", lambda url, timeout: Response(url))
    assert run(tool, tiny) == 1
    err = capsys.readouterr().err
    assert "someone/tiny/meshes/lid.obj" in err and "0" * 40 in err and blob in err
    assert urls and all(u.startswith("https://raw.githubusercontent.com/someone/tiny/") for u in urls)
    assert not tiny["out"].exists() or not any(p.is_file() for p in tiny["out"].rglob("*"))


def test_bad_arguments_and_a_missing_root_say_what_to_do(tiny, tmp_path, capsys):
    tool = load_tool()
    with pytest.raises(SystemExit) as e:
        run(tool, tiny, "--mirrors", str(tmp_path / "nowhere"))
    assert e.value.code == 2 and "--mirrors" in capsys.readouterr().err
    with pytest.raises(InputError, match="fetch_real_unknowns"):
        real_unknowns(tmp_path / "nowhere", "test")
    with pytest.raises(InputError, match="fetch_real_unknowns"):
        open_dataset("real_unknowns", tmp_path, "val")  # a root without the split
    with pytest.raises(InputError, match="fetch_real_unknowns"):
        real_unknowns(tmp_path, "train")  # a valid split not rebuilt here
    with pytest.raises(InputError, match="train, val, test"):
        real_unknowns(tmp_path, "cross")
