# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""tools/load.sh, the machine's load for the tests under load: it keeps cores busy, stops by
itself after its seconds, stops its workers when killed, and refuses bad arguments."""
import signal
import subprocess
from pathlib import Path

LOAD = Path(__file__).resolve().parents[1] / "tools" / "load.sh"


def test_the_load_stops_by_itself_and_refuses_bad_arguments():
    done = subprocess.run(["bash", str(LOAD), "--cores", "1", "--seconds", "1"], capture_output=True,
                          text=True, timeout=60)
    assert done.returncode == 0 and "1 busy cores for 1 s" in done.stderr, done.stderr
    for args in (["--cores", "0"], ["--seconds", "-1"], ["--bogus"]):
        bad = subprocess.run(["bash", str(LOAD), *args], capture_output=True, text=True, timeout=60)
        assert bad.returncode == 2 and "usage" in bad.stderr, (args, bad.stderr)


def test_a_killed_load_takes_its_workers_with_it():
    proc = subprocess.Popen(["bash", str(LOAD), "--cores", "2", "--seconds", "600"], stderr=subprocess.PIPE,
                            text=True)
    assert "2 busy cores" in proc.stderr.readline()  # its workers are started
    workers = subprocess.run(["ps", "-o", "pid=", "--ppid", str(proc.pid)], capture_output=True, text=True)
    pids = [int(p) for p in workers.stdout.split()]
    assert len(pids) == 2
    proc.send_signal(signal.SIGTERM)
    assert proc.wait(timeout=60) == 143
    for pid in pids:  # each `timeout` worker and its loop are gone
        assert subprocess.run(["ps", "-p", str(pid)], capture_output=True).returncode == 1
