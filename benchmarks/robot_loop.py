# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""The loop as a robot runs it: a 640x480 depth camera in another process, procedural test
objects standing on an opaque floor, the recognizer node with its defaults, over topics.

Two cameras, each its own process: `ideal` (exact depth in 16UC1 millimetres) and `realistic`
(a RealSense's Kinect-like noise, dropout and flying pixels, and 2 degrees of arm error). Each
recognises the same seeded test objects; an episode's answer is its recognition/result.
Writes docs/results/robot_loop.json. Last line is JSON:
{"ideal": acc, "realistic": acc, "objects": n, "cameras": {name: {"acc", "statuses",
"mean_views", "s_per_episode"}}}.
"""
import argparse
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from common import emit, private_domain, shipped_checkpoint, stop_processes

from active_recognition.evaluation.report import write_json
from active_recognition.options.command_options import DemoOptions
from active_recognition.options.flags_and_parameters import add_flags

ROOT = Path(__file__).resolve().parents[1]
PROFILE = ROOT / "config" / "fastdds_large_frames.xml"
VGA = {"width": 640, "height": 480, "fx": 385.0, "fy": 385.0, "encoding": "16UC1",
       "min_range": 0.2, "max_range": 10.0, "floor": True, "image_qos": "sensor_data"}
CAMERAS = {"ideal": VGA,
           "realistic": {**VGA, "noise": "kinect", "dropout": 0.03, "edge_dropout": 75.0,
                         "pose_error_deg": 2.0}}


def camera_process(name, params, seed, log):
    """The simulated camera node of `name` in its own process and namespace, its output to the
    open file `log`."""
    env = {**os.environ, "FASTRTPS_DEFAULT_PROFILES_FILE": str(PROFILE)}
    args = [a for k, v in {**params, "seed": seed}.items()
            for a in ("-p", f"{k}:={str(v).lower() if isinstance(v, bool) else v}")]
    return subprocess.Popen([sys.executable, "-m", "active_recognition.nodes.simulated_camera",
                             "--ros-args", "-r", f"__ns:=/{name}", *args],
                            env=env, stdout=log, stderr=subprocess.STDOUT)


def log_tail(log, lines=8):
    """The last lines the camera process wrote, for an error message."""
    log.flush()
    return "".join(Path(log.name).read_text(errors="replace").splitlines(True)[-lines:]) or "(nothing)"


def show(executor, camera, index, tries=3, wait=10.0):
    """Ask the camera process to show object `index`; True once it answered. Setting the index is
    idempotent, so a request whose response DDS dropped ("failed to send response (timeout)"
    in the camera's log) is sent again."""
    from rclpy.parameter import Parameter

    from active_recognition.nodes.demo import spin_until
    for _ in range(tries):
        done = camera.set_parameters([Parameter("index", value=index)])
        if spin_until(executor, done.done, wait):
            refused = [r.reason for r in done.result().results if not r.successful]
            if refused:
                raise RuntimeError(f"the camera refused object {index}: {'; '.join(refused)}")
            return True
    return False


def run_camera(name, objects, seed, timeout):
    """Every object once through camera `name`: (answers, results, seconds per episode)."""
    from rclpy.parameter import Parameter
    from rclpy.parameter_client import AsyncParameterClient

    from active_recognition.datasets import default_cache_dir, open_dataset
    from active_recognition.nodes.demo import DemoClient, recognize, ros_session, spin_until
    from active_recognition.nodes.recognizer import Recognizer

    test = open_dataset("procedural", split="test", cache_dir=default_cache_dir())
    log = tempfile.NamedTemporaryFile("w+", prefix=f"{name}_camera_", suffix=".log")
    proc = camera_process(name, CAMERAS[name], seed, log)
    try:
        with ros_session() as (ctx, executor):
            recognizer = Recognizer(context=ctx, namespace=name,
                                    parameter_overrides=[Parameter("seed", value=seed),
                                                         shipped_checkpoint()])  # procedural objects
            client = DemoClient(context=ctx, namespace=name)
            camera = AsyncParameterClient(client, f"/{name}/simulated_camera")
            for node in (recognizer, client):
                executor.add_node(node)
            ready = spin_until(executor, lambda: camera.services_are_ready(), 120)
            if not ready or not spin_until(executor, client.reset.service_is_ready, 30):
                raise RuntimeError(f"the {name} camera process did not come up; its log ends:\n"
                                   f"{log_tail(log)}")
            answers, results, seconds = [], [], []
            for i in objects:
                if not show(executor, camera, int(i)):
                    raise RuntimeError(f"the {name} camera did not take object {i} in 3 tries "
                                       f"(alive: {proc.poll() is None}); its log ends:\n{log_tail(log)}")
                start = time.perf_counter()
                result = recognize(executor, client, timeout=timeout)
                seconds.append(time.perf_counter() - start)
                results.append(result or {"status": "timeout", "label": "", "views": 0})
                answers.append(results[-1]["label"] == test.classes[test.items[i][1]])
            return answers, results, seconds
    finally:
        stop_processes([proc])
        log.close()


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--objects", type=int, default=40, help="procedural test objects (seeded draw)")
    add_flags(ap, DemoOptions, ["seed"])
    ap.add_argument("--cameras", nargs="*", default=list(CAMERAS), choices=list(CAMERAS))
    ap.add_argument("--timeout", type=float, default=60.0, help="seconds an episode may take")
    # --out by hand: a fixed default, written by every run (no partial-run guard)
    ap.add_argument("--out", default=str(ROOT / "docs/results/robot_loop.json"),
                    help="JSON to write ('' = none)")
    args = ap.parse_args(argv)
    private_domain()
    os.environ.setdefault("ROS_AUTOMATIC_DISCOVERY_RANGE", "LOCALHOST")
    from active_recognition.datasets import default_cache_dir, open_dataset
    n = len(open_dataset("procedural", split="test", cache_dir=default_cache_dir()))
    if not 1 <= args.objects <= n:
        ap.error(f"--objects must be 1..{n}")
    objects = np.sort(np.random.default_rng(args.seed).permutation(n)[:args.objects])
    report = {}
    for name in args.cameras:
        answers, results, seconds = run_camera(name, objects, args.seed, args.timeout)
        statuses = {s: sum(r["status"] == s for r in results) for s in {r["status"] for r in results}}
        report[name] = {"acc": float(np.mean(answers)), "statuses": statuses,
                        "mean_views": float(np.mean([r["views"] for r in results])),
                        "s_per_episode": float(np.median(seconds))}
        print(f"{name:>10}: accuracy {report[name]['acc']:.3f} over {len(objects)} objects, "
              f"statuses {statuses}, {report[name]['mean_views']:.2f} views, "
              f"{report[name]['s_per_episode']:.2f} s an episode (median)")
    result = {**{k: v["acc"] for k, v in report.items()}, "objects": len(objects), "cameras": report}
    if args.out:
        write_json(Path(args.out), result)
    emit(result)


if __name__ == "__main__":
    main()
