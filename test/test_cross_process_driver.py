# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""The recognizer through a camera published as a plain driver publishes one, across processes
(benchmarks/driver_camera.py): 640x480 16UC1 frames, ROS's default QoS, Fast DDS's defaults (no
profile), each pose published before its image, the order in which Fast DDS loses a pose beside
the frame and resends it only at its next heartbeat, 3 s on. The recognizer, started as users
start it with its defaults, answers every goal, asking again for a view whose pose is late."""
import os

import numpy as np

import pytest

from conftest import import_ros, load_benchmark

from active_recognition.runtime.timing import Timing

import_ros("rclpy")
if not os.environ.get("CI"):
    pytest.importorskip("active_recognition_interfaces.action")

pytestmark = pytest.mark.slow  # two processes that load torch, a model, a renderer

GOALS = 8
TIMEOUT = 20.0  # seconds a goal may take to answer; a pose lost for its heartbeat costs 3 s a view


def test_every_goal_through_a_driver_camera_that_publishes_each_pose_first_is_answered(tmp_path):
    bench = load_benchmark("driver_camera")
    shown = bench.objects("procedural", None, GOALS, seed=3)
    rows, figures, diagnostics = bench.run("procedural", None, shown, 3, [], True, TIMEOUT,
                                           tmp_path)
    print({k: figures[k] for k in ("unanswered", "s_per_view", "node_wait_ms", "pose_ms")})
    assert [r["answered"] for r in rows] == [True] * GOALS, rows
    assert all(r["status"] in ("recognized", "unsure", "unknown") for r in rows), rows
    assert all(len(r["view_waits"]) == r["views"] > 0 for r in rows), rows  # each view's split
    assert figures["views"] == sum(r["views"] for r in rows)
    # without the re-ask, 3 poses in 10 (more on a busy machine: docs/results/pose_loss.json) are
    # lost and each is waited for until pose_wait, 3.5 s; with it, a lost pose costs the camera's
    # round trip once more for each try. So the views' pose waits stay within (re-asks + views)
    # round trips, the round trip as this run's camera gave it (its image wait, 90th percentile,
    # twice), whatever the load; a wait for pose_wait costs 3.5 s and breaks it
    assert {"view image wait p99 (ms)", "view pose wait p99 (ms)"} <= set(diagnostics), diagnostics
    views = [v for r in rows for v in r["view_waits"]]
    trip = 2 * (float(np.percentile([v["image"] for v in views], 90)) + Timing().pose_reask)
    asked_again = int(float(diagnostics["views asked again for a late pose"]))
    waited = sum(v["pose"] for v in views)
    assert waited <= (asked_again + len(views)) * trip, (waited, asked_again, trip, views)
