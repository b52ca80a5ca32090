# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""benchmarks/soak.py's short form: 50 goals in a row through the action, the recognizer and the
camera in processes of their own, with dropped frames, late TF, cancels, preemptions and the
camera killed and started again twice. Every goal answers, every cancel the node accepted ends
CANCELED, and the node's memory, threads and open files stay flat (the machine is loaded by the
suite itself, so no load of its own)."""
import json
import subprocess
import sys
from pathlib import Path

import pytest

from conftest import import_ros

ROOT = Path(__file__).resolve().parents[1]


@pytest.mark.slow
def test_fifty_goals_with_faults_all_answer_and_the_node_stays_flat(tmp_path):
    import_ros("active_recognition_interfaces.action")
    out = tmp_path / "soak.json"
    done = subprocess.run([sys.executable, str(ROOT / "benchmarks" / "soak.py"), "--goals", "50",
                           "--kill-every", "25", "--no-load", "--out", str(out)],
                          capture_output=True, text=True, timeout=1500, cwd=ROOT / "benchmarks")
    assert done.returncode == 0, done.stdout[-2000:] + done.stderr[-3000:]
    soak = json.loads(out.read_text())
    assert soak["goals"] == soak["answered"] == 50, soak["states"]
    assert soak["faults"]["kill"] == 2 and soak["faults"]["cancel"] > 0 and soak["faults"]["preempt"] > 0
    assert soak["cancels_accepted_canceled"] == soak["cancels_accepted"], \
        [r for r in soak["records"] if r.get("cancel") == "accepted" and r["state"] != "CANCELED"]
    first, last = soak["node_usage"]["1"], soak["node_usage"]["50"]
    assert last["rss_mb"] <= 1.05 * first["rss_mb"], soak["node_usage"]
    assert (last["threads"], last["fds"]) == (first["threads"], first["fds"]), soak["node_usage"]
    assert soak["accuracy_whole"] >= 0.8, [r for r in soak["records"] if r["fault"] == "none"]
