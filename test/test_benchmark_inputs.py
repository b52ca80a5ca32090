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

"""The benchmarks that write tables (planners.py, camera_robustness.py and others) as a user runs them: bad input ends
in one line naming the thing and the reason, before any long work; a partial run never
overwrites the committed figures; a checkpoint's error crosses a process pool whole."""
import pickle
import subprocess
import sys
from dataclasses import replace
from pathlib import Path

import pytest
from conftest import load_benchmark

from active_recognition.checkpoint import CheckpointError
from active_recognition.datasets import default_cache_dir, open_dataset
from active_recognition.evaluate import EvalConfig, halves

ROOT = Path(__file__).resolve().parents[1]


def run(script, *args):
    out = subprocess.run([sys.executable, str(ROOT / "benchmarks" / script), *map(str, args)],
                         capture_output=True, text=True, timeout=300)
    return out.returncode, out.stderr


@pytest.mark.parametrize("script, args, said", [
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
    ("size_prior.py", ["--root", "{tmp}/nope", "--out", "{tmp}/o"],
     "modelnet dataset root {tmp}/nope: no such directory"),
    ("open_set.py", ["--root", "{tmp}/nope", "--out", "{tmp}/o"],
     "modelnet dataset root {tmp}/nope: no such directory"),
    ("open_set.py", ["--root", "{tmp}", "--objects", "5"], "a partial run (--objects) would overwrite the committed"),
    ("open_set.py", ["--root", "{tmp}", "--known-rate", "1.5", "--out", "{tmp}/o"], "--known-rate must lie in (0, 1]"),
    ("camera_robustness.py", ["--workers", "0"], "--workers must be at least 1, got 0"),
    ("camera_robustness.py", ["--rows", "clean"], "a partial run (--rows) would overwrite the committed"),
])
def test_bad_input_ends_in_one_line_and_writes_nothing(tmp_path, script, args, said):
    (tmp_path / "garbage.pt").write_bytes(b"\x80not a checkpoint" * 8)
    before = {p: p.stat().st_mtime_ns for p in (ROOT / "docs").rglob("*") if p.is_file()}
    code, err = run(script, *(a.format(tmp=tmp_path) for a in args))
    assert code == 2, err
    assert "Traceback" not in err
    assert err.strip().splitlines()[-1].startswith(f"{script}: error: {said.format(tmp=tmp_path)}"), err
    assert not (tmp_path / "o").exists() and not (tmp_path / "c.json").exists()
    assert {p: p.stat().st_mtime_ns for p in (ROOT / "docs").rglob("*") if p.is_file()} == before


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
