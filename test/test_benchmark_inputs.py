# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""The benchmarks that write tables (planners.py, camera_robustness.py and others) as a user runs them: bad input ends
in one line naming the thing and the reason, before any long work; a partial run never
overwrites the committed figures; a checkpoint's error crosses a process pool whole."""
import os
import pickle
import sys
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
from conftest import load_benchmark, run_side_by_side

from active_recognition.datasets import default_cache_dir, open_dataset
from active_recognition.evaluation.evaluate import EvalConfig, halves
from active_recognition.model.checkpoint import CheckpointError

ROOT = Path(__file__).resolve().parents[1]
PROCEDURAL = ROOT / "active_recognition/checkpoints/procedural.pt"  # a single network


BAD_INPUT = [
    ("robot_seconds.py", ["--per-object", "{tmp}/nope.csv", "--out", "{tmp}/r.json"],
     "--per-object {tmp}/nope.csv: no such file"),
    ("robot_seconds.py", ["--rad-per-s", "0", "--out", "{tmp}/r.json"], "rad_per_s must be"),
    ("robot_seconds.py", ["--add", "{tmp}/x.csv", "--out", "{tmp}/r.json"],
     "--add {tmp}/x.csv: NAME=CSV of an evaluation's per_object.csv expected"),
    ("robot_seconds.py", ["--budget-entropy", "nan", "--out", "{tmp}/r.json"],
     "--budget-entropy must be a number of nats in [0, 10], got nan"),
    ("robot_seconds.py", ["--budget-entropy", "0.1", "--out", "{tmp}/r.json"],
     "--budget-entropy applies to the episodes --add names"),
    ("seconds_validation.py", ["--root", "{tmp}/nope", "--out", "{tmp}/o"],
     "modelnet dataset root {tmp}/nope: no such directory"),
    ("seconds_validation.py", ["--root", "{tmp}", "--costs", "1", "2", "--out", "{tmp}/o"],
     "--costs must include 0"),
    ("seconds_validation.py", ["--root", "{tmp}", "--objects", "5"],
     "a partial run (--objects) would overwrite the committed"),
    ("camera_parts.py", ["--root", "{tmp}/nope", "--out", "{tmp}/o"],
     "modelnet dataset root {tmp}/nope: no such directory"),
    ("driver_camera.py", ["--dataset", "modelnet", "--root", "{tmp}/nope", "--out", "{tmp}/o"],
     "modelnet dataset root {tmp}/nope: no such directory"),
    ("driver_camera.py", ["--episodes", "3"], "a partial run (--episodes) would overwrite the committed"),
    ("camera_parts.py", ["--root", "{tmp}", "--objects", "5"],
     "a partial run (--objects) would overwrite the committed"),
    ("open_set_camera.py", ["--root", "{tmp}", "--unknowns", "real_unknowns", "--unknowns-root", "{tmp}/nope",
                            "--out", "{tmp}/o"], "real_unknowns root {tmp}/nope: no such directory; rebuild"),
    ("planners.py", ["--dataset", "modelnet", "--root", "{tmp}/nope", "--out", "{tmp}/o"],
     "modelnet dataset root {tmp}/nope: no such directory"),
    ("planners.py", ["--checkpoint", "{tmp}/garbage.pt", "--out", "{tmp}/o"],
     "checkpoint {tmp}/garbage.pt: unreadable"),
    ("planners.py", ["--objects", "100000", "--out", "{tmp}/o"], "--objects must be 0 (all) .. "),
    ("planners.py", ["--objects", "5"], "a partial run (--objects) would overwrite the committed"),
    ("planners.py", ["--objects", "5", "--out", "{tmp}/o", "--ship"], "--ship records what the whole"),
    ("camera_robustness.py", ["--dataset", "modelnet", "--root", "{tmp}/nope", "--out", "{tmp}/c.json"],
     "modelnet dataset root {tmp}/nope: no such directory"),
    ("camera_robustness.py", ["--checkpoint", "{tmp}/garbage.pt", "--objects", "1", "--rows", "clean",
                              "--out", "{tmp}/c.json"], "checkpoint {tmp}/garbage.pt: unreadable"),
    ("dataset_generation.py", ["--dataset", "modelnet", "--root", "{tmp}/nope"],
     "modelnet dataset root {tmp}/nope: no such directory"),
    ("dataset_difficulty.py", ["--dataset", "modelnet", "--root", "{tmp}/nope"],
     "modelnet dataset root {tmp}/nope: no such directory"),
    ("size_prior_weight.py", ["--root", "{tmp}/nope", "--out", "{tmp}/o"],
     "modelnet dataset root {tmp}/nope: no such directory"),
    ("open_set_auroc.py", ["--root", "{tmp}/nope", "--out", "{tmp}/o"],
     "modelnet dataset root {tmp}/nope: no such directory"),
    ("open_set_auroc.py", ["--root", "{tmp}", "--objects", "5"],
     "a partial run (--objects) would overwrite the committed"),
    ("open_set_auroc.py", ["--root", "{tmp}", "--known-rate", "1.5", "--out", "{tmp}/o"],
     "--known-rate must lie in (0, 1]"),
    ("open_set_auroc.py", ["--root", "{tmp}", "--min-elevation", "0"],
     "a partial run (--min-elevation) would overwrite the committed"),
    ("open_set_camera.py", ["--root", "{tmp}/nope", "--out", "{tmp}/o"],
     "modelnet dataset root {tmp}/nope: no such directory"),
    ("open_set_camera.py", ["--root", "{tmp}", "--objects", "5"],
     "a partial run (--objects) would overwrite the committed"),
    ("open_set_camera.py", ["--root", "{tmp}", "--checkpoint", "{tmp}/garbage.pt", "--out", "{tmp}/o"],
     "checkpoint {tmp}/garbage.pt: unreadable"),
    ("open_set_scores.py", ["--root", "{tmp}/nope", "--out", "{tmp}/o"],
     "modelnet dataset root {tmp}/nope: no such directory"),
    ("open_set_scores.py", ["--root", "{tmp}", "--objects", "50"],
     "a partial run (--objects) would overwrite the committed"),
    ("open_set_scores.py", ["--root", "{tmp}", "--objects", "3"], "--objects must be at least 10"),
    ("open_set_scores.py", ["--root", "{tmp}", "--val-objects", "-1", "--out", "{tmp}/o"],
     "--val-objects must be 0 (all) or more, got -1"),
    ("validation_camera.py", ["--root", "{tmp}/nope", "--out", "{tmp}/o"],
     "modelnet dataset root {tmp}/nope: no such directory"),
    ("validation_camera.py", ["--root", "{tmp}", "--starts", "0", "--out", "{tmp}/o"],
     "--starts must be at least 1 and --objects at least 0"),
    ("validation_camera.py", ["--root", "{tmp}", "--objects", "5"],
     "a partial run (--objects) would overwrite the committed"),
    ("validation_camera.py", ["--root", "{tmp}", "--objects", "5", "--ship", "--out", "{tmp}/o"],
     "--ship records what the whole benchmark chose for the shipped model; leave out --objects"),
    ("validation_camera.py", ["--root", "{tmp}", "--planners", "bogus", "--out", "{tmp}/o"],
     "--planners: bogus not among the node's planners"),
    ("validation_camera.py", ["--root", "{tmp}", "--reference", "bogus", "--out", "{tmp}/o"],
     "--reference: bogus not among the node's planners"),
    ("validation_camera.py", ["--root", "{tmp}", "--reference", "imitation", "--ship"],
     "--ship records what the whole benchmark chose for the shipped model; leave out --reference"),
    ("validation_camera.py", ["--root", "{tmp}", "--planners", "random", "--ship"],
     "--ship records what the whole benchmark chose for the shipped model; leave out --planners"),
    ("validation_camera.py", ["--root", "{tmp}", "--ship", "--out", "{tmp}/o"],
     "--ship records the choice beside its committed figures"),
    ("member_scores.py", ["--root", "{tmp}", "--folds", "0", "--out", "{tmp}/o"],
     "--val-objects must be 0 (all) or more and --folds at least 1, got 0, 0"),
    ("member_scores.py", ["--root", "{tmp}", "--val-objects", "5"],
     "a partial run (--val-objects) would overwrite the committed"),
    ("member_scores.py", ["--root", "{tmp}", "--checkpoint", "{tmp}/garbage.pt", "--out", "{tmp}/o"],
     "checkpoint {tmp}/garbage.pt: unreadable"),
    ("member_scores.py", ["--root", "{tmp}", "--checkpoint", str(PROCEDURAL), "--out", "{tmp}/o"],
     f"{PROCEDURAL}: not an ensemble"),
    ("camera_robustness.py", ["--workers", "0"], "--workers must be at least 1, got 0"),
    ("camera_robustness.py", ["--rows", "clean"], "a partial run (--rows) would overwrite the committed"),
]


def docs_files():
    return {p: p.stat().st_mtime_ns for p in (ROOT / "docs").rglob("*") if p.is_file()}


@pytest.fixture(scope="module")
def bad_runs(tmp_path_factory):
    """Every run of BAD_INPUT, side by side, each in a folder of its own: ({(script, args):
    (folder, CompletedProcess)}, the docs/ files' times before and after them all)."""
    folders = [tmp_path_factory.mktemp("bad") for _ in BAD_INPUT]
    for tmp in folders:
        (tmp / "garbage.pt").write_bytes(b"\x80not a checkpoint" * 8)
    before = docs_files()
    done = run_side_by_side([[sys.executable, str(ROOT / "benchmarks" / script), *(a.format(tmp=tmp) for a in args)]
                             for (script, args, _), tmp in zip(BAD_INPUT, folders)], timeout=300)
    runs = {(script, tuple(args)): run for (script, args, _), run in zip(BAD_INPUT, zip(folders, done))}
    return runs, before, docs_files()


@pytest.mark.slow
@pytest.mark.parametrize("script, args, said", BAD_INPUT)
def test_bad_input_ends_in_one_line_and_writes_nothing(bad_runs, script, args, said):
    runs, before, after = bad_runs
    tmp_path, p = runs[script, tuple(args)]
    code, err = p.returncode, p.stderr
    assert code == 2, err
    assert "Traceback" not in err
    assert err.strip().splitlines()[-1].startswith(f"{script}: error: {said.format(tmp=tmp_path)}"), err
    assert not (tmp_path / "o").exists() and not (tmp_path / "c.json").exists()
    assert after == before  # not one of the runs wrote to the committed figures


def test_a_checkpoint_error_crosses_a_process_pool_whole():
    """Raised in a worker, it reaches the parent as itself; before, unpickling called
    __init__(message) and the pool broke with a TypeError in place of the reason."""
    e = pickle.loads(pickle.dumps(CheckpointError("/models/x.pt", "not a model")))
    assert type(e) is CheckpointError and str(e) == "checkpoint /models/x.pt: not a model"
    assert (e.path, e.reason) == ("/models/x.pt", "not a model")


def test_only_docs_results_counts_as_committed(tmp_path):
    common = load_benchmark("common")
    assert common.committed(common.RESULTS / "modelnet10" / "summary.json")
    assert common.committed(common.RESULTS / "twins-yaw45")
    assert not common.committed(tmp_path / "summary.json")
    assert not common.committed(common.RESULTS.parent / "RESULTS.md")


@pytest.mark.parametrize("objects, planners", [(4, ("random", "fixed")), (4, ("random",)),
                                               (100000, ("random", "fixed")), (100000, ("random",)),
                                               (0, ("random", "fixed"))])
def test_a_small_run_chooses_its_default_on_as_many_validation_objects(
        monkeypatch, tmp_path, objects, planners):
    """--objects N scores the planners on N validation objects too, at most the split holds where
    they are scored (with a fixed path, the half it was not picked on); 0 keeps all of them."""
    planners_py = load_benchmark("planners")
    seen = []

    def fake_evaluate(cfg):
        seen.append(cfg)
        return {}
    monkeypatch.setattr(planners_py, "evaluate", fake_evaluate)
    monkeypatch.setattr(planners_py, "summary", lambda _: {"acc": {p: {"3": 0.5, "6": 0.5, "9": 0.5}
                                                                   for p in planners}})
    cfg = replace(EvalConfig(), planners=planners + ("oracle",), objects=objects)
    planners_py.choose_default(cfg, tmp_path)
    total = len(open_dataset("procedural", None, "val", cache_dir=default_cache_dir()))
    held = len(halves(total, cfg.seed)[1]) if "fixed" in planners else total
    assert held < total or "fixed" not in planners
    assert seen[0].split == "val" and seen[0].planners == planners
    assert seen[0].objects == (min(objects, held) if objects else 0)


def test_planners_ship_refuses_a_modelnet_model_that_records_no_default(tmp_path, capsys):
    """ModelNet10's default planner is chosen through the camera (validation_camera.py --ship);
    planners.py --ship must not overwrite it with its renders' rule when a fresh model records
    none: it refuses, naming the file and the command that records it. A model that records one,
    a run without --ship and another dataset's model go on."""
    import argparse
    from types import SimpleNamespace

    import torch

    from active_recognition.model import checkpoint

    planners_py = load_benchmark("planners")
    bare = tmp_path / "fresh.pt"
    ckpt = checkpoint.read(checkpoint.shipped("procedural"))
    ckpt.pop("default_planner", None)
    torch.save(ckpt, bare)
    ap = argparse.ArgumentParser(prog="planners.py")
    with pytest.raises(SystemExit):
        planners_py.refuse_unrecorded_default(ap, SimpleNamespace(ship=True, dataset="modelnet"), str(bare))
    err = capsys.readouterr().err
    assert "fresh.pt records no default planner" in err and "validation_camera.py --root DIR --ship" in err
    recorded = checkpoint.shipped("procedural")
    assert checkpoint.read(recorded).get("default_planner")
    planners_py.refuse_unrecorded_default(ap, SimpleNamespace(ship=True, dataset="modelnet"), str(recorded))
    planners_py.refuse_unrecorded_default(ap, SimpleNamespace(ship=False, dataset="modelnet"), str(bare))
    planners_py.refuse_unrecorded_default(ap, SimpleNamespace(ship=True, dataset="procedural"), str(bare))


def test_a_benchmark_takes_a_dds_domain_above_the_test_suites_unless_one_is_set(monkeypatch):
    common = load_benchmark("common")
    taken = set()
    for seed in range(40):
        monkeypatch.delenv("ROS_DOMAIN_ID", raising=False)
        taken.add(common.private_domain(np.random.default_rng(seed)))
    assert min(taken) >= 101 and max(taken) <= 200 and len(taken) > 20  # test/conftest.py's are 1-90
    monkeypatch.setenv("ROS_DOMAIN_ID", "7")
    assert common.private_domain() == 7 and os.environ["ROS_DOMAIN_ID"] == "7"
