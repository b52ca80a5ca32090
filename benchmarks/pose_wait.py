# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""How long images wait for their measured pose, for the default of pose_wait: the recognizer
here (pose_wait 10 s, so that nothing is given up), the simulated camera in another process at
640x480 with the RealSense preset, reliable QoS and Fast DDS's defaults (no profile), as a
RealSense driver publishes. N episodes on seeded procedural test objects, once with
`pose_source: topic` (the camera publishes camera/pose) and once with `pose_source: tf` (it
broadcasts its optical frame and publishes no camera/pose).

Figures of each: the node's controller.waited (seconds an image waited for its pose, from its
arrival to its pose's: count, p50, p99, max in ms), the share of classified images matched to a
measured pose, accuracy. With `topic`, an image whose pose came first waits not at all and is
not in controller.waited; with `tf` every image is (0 when its transform was there). A Fast DDS
profile in FASTRTPS_DEFAULT_PROFILES_FILE reaches both processes (such a run names its --out).

    python benchmarks/pose_wait.py [--episodes 20] [--sources topic tf] [--out FILE]

Last line is JSON, also written to docs/results/pose_wait.json."""
import argparse
import os
import platform
import subprocess
import sys
import tempfile
import time
from dataclasses import asdict
from pathlib import Path

import numpy as np
from common import RESULTS, add_common_flags, emit, output, private_domain, show_object, stop_processes

from active_recognition.runtime.controller import Timing

ROOT = Path(__file__).resolve().parents[1]
PROFILE = ROOT / "config" / "fastdds_large_frames.xml"
START_S = 180  # a camera process loading torch and a renderer beside others on a busy machine
DEFAULT_POSE_WAIT = Timing().pose_wait  # the default these figures are for
MATCHED_KEY = "images matched to a measured pose (%)"  # on /diagnostics
# pose_source: the camera's parameters beside the RealSense preset (its namespace: pose_<source>)
SETUPS = {"topic": {"image_qos": "reliable"},
          "tf": {"image_qos": "reliable", "publish_tf": True, "publish_pose": False}}


def cpu():
    """(lscpu's model name, its avx flags)."""
    info = subprocess.run(["lscpu"], capture_output=True, text=True).stdout
    lines = dict(line.split(":", 1) for line in info.splitlines() if ":" in line)
    return (lines.get("Model name", platform.processor()).strip(),
            [f for f in lines.get("Flags", "").split() if f.startswith("avx")])


def ros_args(params):
    return [a for k, v in params.items()
            for a in ("-p", f"{k}:={str(v).lower() if isinstance(v, bool) else v}")]


def camera_params(seed, **extra):
    """Every field of the RealSense preset (640x480), procedural test objects, and `extra`."""
    from active_recognition.simulation.depth_sensor import sensor_config
    return {**asdict(sensor_config("realsense")), "dataset": "procedural", "split": "test",
            "seed": seed, **extra}


def start_cameras(setups, logs):
    """{namespace: (camera parameters, Fast DDS large-frames profile?)} -> {namespace: Popen}: a
    `python -m active_recognition.nodes.simulated_camera` process each, all started at once, its
    output to logs/<namespace>.log."""
    procs = {}
    for ns, (params, profile) in setups.items():
        env = dict(os.environ)  # ROS_DOMAIN_ID and the discovery range
        if profile:  # best-effort 640x480 frames go through shared memory only with it
            env["FASTRTPS_DEFAULT_PROFILES_FILE"] = str(PROFILE)
        log = Path(logs) / f"{ns}.log"
        with open(log, "w") as out:
            procs[ns] = subprocess.Popen(
                [sys.executable, "-m", "active_recognition.nodes.simulated_camera", "--ros-args",
                 "-r", f"__ns:=/{ns}", *ros_args(params)],
                env=env, stdout=out, stderr=subprocess.STDOUT)
        procs[ns].log = log
    return procs


def tail(proc, lines=15):
    """The end of a start_cameras process's log, for an error message."""
    text = Path(proc.log).read_text(errors="replace").splitlines()[-lines:]
    state = "running" if proc.poll() is None else f"exit {proc.returncode}"
    return f"{proc.log} ({state}):\n" + "\n".join(text)


def objects(count, seed):
    """`count` procedural test objects, a seeded draw: [(index, true class)]."""
    from active_recognition.datasets import default_cache_dir, open_dataset
    test = open_dataset("procedural", split="test", cache_dir=default_cache_dir())
    order = np.random.default_rng(seed).choice(len(test), count, replace=False)
    return [(int(i), test.classes[test.items[i][1]]) for i in order]


def run(ns, shown, recognizer, seed, camera=None, timeout=30.0):
    """One episode per object of `shown` ([(index, class)]) through the camera process in
    namespace `ns` (its `index` parameter set before each), recognised by a Recognizer made here
    with `recognizer`'s parameters beside the shipped procedural model, every callback in one
    thread as `rclpy.spin` runs it. -> {"results", "right", "counts", "waited" (s), "refused",
    "diagnostics" (the node's last /diagnostics values, once they count every image),
    "seconds"}."""
    from diagnostic_msgs.msg import DiagnosticArray
    from rclpy.parameter import Parameter
    from rclpy.parameter_client import AsyncParameterClient

    import msg_adapters as ma
    from active_recognition.model.checkpoint import shipped
    from active_recognition.nodes.demo import DemoClient, recognize, ros_session, spin_until
    from active_recognition.nodes.recognizer import Recognizer

    def fail(why):
        raise RuntimeError(why + (f"\n{tail(camera)}" if camera is not None else ""))

    with ros_session(one_thread=True) as (ctx, executor):
        given = {"checkpoint": str(shipped("procedural")), "seed": seed, **recognizer}
        rec = Recognizer(context=ctx, namespace=ns,
                         parameter_overrides=[Parameter(k, value=v) for k, v in given.items()])
        client = DemoClient(context=ctx, namespace=ns)
        arrays = []
        client.create_subscription(DiagnosticArray, "/diagnostics", arrays.append, 10)
        params = AsyncParameterClient(client, f"/{ns}/simulated_camera")
        for node in (rec, client):
            executor.add_node(node)
        if not spin_until(executor, lambda: params.services_are_ready() and
                          client.reset.service_is_ready() and
                          client.count_publishers(f"/{ns}/depth/image") > 0, START_S):
            fail(f"the camera process in /{ns} did not come up within {START_S} s")
        began, results, right = time.monotonic(), [], []
        for index, truth in shown:
            taken = show_object(executor, params, index)
            if taken is None:
                fail(f"the camera in /{ns} did not take object {index} in 3 tries")
            if not all(r.successful for r in taken):
                fail(f"the camera in /{ns} refused object {index}: {taken}")
            result = recognize(executor, client, timeout=timeout) or \
                {"status": "no result", "label": "", "views": 0}
            results.append({"index": index, "truth": truth, **result})
            right.append(result["status"] in ("recognized", "unsure") and result["label"] == truth)
        seconds = time.monotonic() - began
        name = f"{rec.get_fully_qualified_name().lstrip('/')}: recognition"
        classified = str(rec.loop.counts["classified"])

        def latest():
            for msg in reversed(arrays):
                for status in msg.status:
                    values = ma.status_values(status)
                    if status.name == name and values.get("images classified") == classified:
                        return values
            return None
        spin_until(executor, lambda: latest() is not None, 5.0)  # published at 1 Hz
        return {"results": results, "right": right, "counts": dict(rec.loop.counts),
                "waited": list(rec.loop.waited), "refused": dict(rec.refuse.counts),
                "diagnostics": latest(), "seconds": seconds}


def waits_ms(waited):
    """{count, p50, p99, max} of waits in seconds, in ms."""
    w = np.asarray(waited, float) * 1e3
    if not len(w):
        return {"count": 0}
    return {"count": int(len(w)), "p50": float(np.percentile(w, 50)),
            "p99": float(np.percentile(w, 99)), "max": float(w.max())}


def figures(done):
    """The figures of one run()."""
    n, waited = done["counts"], np.asarray(done["waited"], float)
    classified, matched = n.get("classified", 0), n.get("matched", 0)
    return {"accuracy": float(np.mean(done["right"])), "classified": classified,
            "matched": matched, "matched_pct": 100.0 * matched / max(classified, 1),
            "diagnostics_matched_pct": (done["diagnostics"] or {}).get(MATCHED_KEY),
            "waited_ms": waits_ms(waited), "waits_over_100ms": int((waited > 0.1).sum()),
            "waits_over_default": int((waited > DEFAULT_POSE_WAIT).sum()),
            "rejected": n.get("rejected", 0), "stale": n.get("stale", 0),
            "refused": done["refused"], "seconds": done["seconds"],
            "statuses": {s: sum(r["status"] == s for r in done["results"])
                         for s in sorted({r["status"] for r in done["results"]})}}


def line(name, f):
    """One run's figures in a line."""
    w = f["waited_ms"]
    waits = (f"{w['count']} waits, p50 {w['p50']:.1f} ms, p99 {w['p99']:.1f} ms, "
             f"max {w['max']:.1f} ms" if w["count"] else "no waits")
    return (f"{name:>5}: accuracy {f['accuracy']:.2f}, matched {f['matched']}/{f['classified']} "
            f"({f['matched_pct']:.1f} %), {waits}, {f['waits_over_default']} over "
            f"{DEFAULT_POSE_WAIT:g} s, {f['seconds']:.0f} s")


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--episodes", type=int, default=20,
                    help="procedural test objects (a seeded draw), one episode each, per source")
    ap.add_argument("--seed", type=int, default=7,
                    help="the objects shown, the camera's noise, the recognizer's first views")
    ap.add_argument("--pose-wait", type=float, default=10.0,
                    help="the recognizer's pose_wait (s): long, so that the whole tail is seen")
    ap.add_argument("--sources", nargs="+", default=list(SETUPS), choices=list(SETUPS),
                    help="pose_source values to run")
    add_common_flags(ap, "out", out="docs/results/pose_wait.json")
    args = ap.parse_args(argv)
    from active_recognition.argument_checks import SEED_MAX
    from active_recognition.datasets import default_cache_dir, open_dataset
    total = len(open_dataset("procedural", split="test", cache_dir=default_cache_dir()))
    if not 1 <= args.episodes <= total:
        ap.error(f"--episodes must be 1..{total} (the procedural test split), got {args.episodes}")
    if not 0 < args.pose_wait <= 60:
        ap.error(f"--pose-wait must lie in (0, 60] s (the parameter's range), "
                 f"got {args.pose_wait:g}")
    if not 0 <= args.seed <= SEED_MAX:
        ap.error(f"--seed must be 0..{SEED_MAX}, got {args.seed}")
    profile = os.environ.get("FASTRTPS_DEFAULT_PROFILES_FILE", "")
    partial = [flag for flag, changed in (
        ("--episodes", args.episodes != 20), ("--seed", args.seed != 7),
        ("--pose-wait", args.pose_wait != 10.0), ("--sources", args.sources != list(SETUPS)),
        ("FASTRTPS_DEFAULT_PROFILES_FILE", bool(profile))) if changed]
    out = output(ap, args.out, RESULTS / "pose_wait.json", partial)
    private_domain()
    os.environ.setdefault("ROS_AUTOMATIC_DISCOVERY_RANGE", "LOCALHOST")
    from active_recognition.evaluation.report import write_json

    shown = objects(args.episodes, args.seed)
    model, avx = cpu()
    result = {"cpu": model, "avx_flags": avx, "cpu_count": os.cpu_count(),
              "episodes": args.episodes, "seed": args.seed, "pose_wait_s": args.pose_wait,
              "default_pose_wait_s": DEFAULT_POSE_WAIT,
              "camera": "simulated_camera in another process, RealSense preset 640x480 16UC1, "
                        "image_qos reliable", "fastdds_profile": profile or "none (defaults)"}
    with tempfile.TemporaryDirectory(prefix="pose_wait_") as logs:
        setups = {f"pose_{source}": (camera_params(args.seed, **SETUPS[source]), False)
                  for source in args.sources}
        procs = start_cameras(setups, logs)
        try:
            for source in args.sources:
                done = run(f"pose_{source}", shown,
                           {"pose_source": source, "pose_wait": args.pose_wait}, args.seed,
                           procs[f"pose_{source}"])
                result[source] = figures(done)
                print(line(source, result[source]), flush=True)
        finally:
            stop_processes(list(procs.values()))
    if out:
        write_json(Path(out), result)
    emit(result)


if __name__ == "__main__":
    main()
