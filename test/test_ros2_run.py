# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""`ros2 run`, `ros2 lifecycle` and `ros2 interface` as a ROS user types them, with the venv that
the README's set-up makes activated and nothing sourced: both executables found in the package's
ament index, a managed recognizer driven through its states, the action's definition shown."""
import re
import subprocess
import time

import pytest
from ros2_cli import RECOGNIZE, Running, nodes_up, ros2, until


def test_ros2_knows_the_package_its_executables_and_its_launch_files(ros2_daemon):
    assert ros2("pkg", "executables", "active_recognition").stdout.split("\n")[:2] == \
        ["active_recognition recognizer", "active_recognition simulated_camera"]
    assert "active_recognition" in ros2("pkg", "list").stdout.split()
    xml = ros2("pkg", "xml", "active_recognition", "--tag", "name")
    assert xml.stdout.strip() == "active_recognition", xml


def test_ros2_interface_show_prints_the_action_as_it_is_defined(ros2_daemon):
    from pathlib import Path

    shown = ros2("interface", "show", RECOGNIZE)
    assert shown.returncode == 0, shown
    source = Path(__file__).resolve().parents[1] / "interfaces" / "active_recognition_interfaces" / "action"
    fields = [line.split("#")[0].strip() for line in (source / "Recognize.action").read_text().splitlines()]
    fields = [f for f in fields if f and f != "---"]
    shown_lines = [line.split("#")[0].strip() for line in shown.stdout.splitlines()]
    assert fields and all(f in shown_lines for f in fields), (fields, shown.stdout)
    # the nested types expanded, as ros2 interface show does: Classification's own fields
    assert any(line.strip().startswith("ClassificationResult[] results") or "results" in line
               for line in shown.stdout.splitlines())


@pytest.mark.slow
def transition(node, label, target, timeout=120):
    """`ros2 lifecycle set NODE LABEL` until `ros2 lifecycle get` says `target`. A call that hangs
    (its request sent before discovery matched the service, on a loaded machine) is stopped, and
    the node's state decides whether to send it again: a set is not repeated once it took."""
    end = time.monotonic() + timeout
    while (state := until(["lifecycle", "get", node], r"^\w+ \[\d+\]$").group(0)) != target:
        assert time.monotonic() < end, f"{node}: {target} not reached by {label}; {state}"
        try:
            done = ros2("lifecycle", "set", node, label, timeout=20)
        except subprocess.TimeoutExpired:
            continue
        assert "Transitioning successful" in done.stdout, done.stdout + done.stderr


def test_ros2_run_starts_both_nodes_and_ros2_lifecycle_drives_a_managed_recognizer(tmp_path, ros2_daemon):
    """`ros2 run` of each executable; with autostart:=false the recognizer waits unconfigured
    until `ros2 lifecycle set` configures and activates it; then a goal sent with
    `ros2 action send_goal` gets its answer; Ctrl-C ends each node with status 0."""
    with Running(["run", "active_recognition", "recognizer", "--ros-args", "-p", "autostart:=false",
                  "-p", "checkpoint:=procedural.pt"], tmp_path / "recognizer.log") as recognizer, \
            Running(["run", "active_recognition", "simulated_camera", "--ros-args", "-p", "index:=3"],
                    tmp_path / "camera.log") as camera:
        nodes_up("/recognizer", "/simulated_camera")
        until(["service", "list"], r"/recognizer/change_state")
        until(["lifecycle", "get", "/recognizer"], r"^unconfigured \[1\]$")
        transition("/recognizer", "configure", "inactive [2]")
        transition("/recognizer", "activate", "active [3]")
        assert ros2("lifecycle", "get", "/recognizer").stdout.strip() == "active [3]"
        done = ros2("action", "send_goal", "/recognize", RECOGNIZE, "{max_views: 3}", timeout=240)
        assert "Goal finished with status:" in done.stdout, done
        status = re.search(r"^\s*status: (\w+)$", done.stdout[done.stdout.rindex("Result:"):], re.M).group(1)
        assert status in ("recognized", "unsure", "unknown"), done.stdout
        assert recognizer.stop() == 0 and camera.stop() == 0
    assert "Traceback" not in recognizer.text() + camera.text(), recognizer.text()[-2000:] + camera.text()[-2000:]
