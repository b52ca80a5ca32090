# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""The recognizer through an independent camera, published as a plain driver publishes one.

The camera (`--serve`, a process of its own): a plain rclpy node that hears next_view, is there
at once, renders the object with the project's renderer (the RealSense preset: 640x480 16UC1)
and publishes depth/camera_info, then depth/image and one camera/pose per image (the pose first,
or last: both orders are run), all stamped like the request, with ROS's default QoS (reliable,
keep-last 10) and Fast DDS's defaults (no profile file: FASTRTPS_DEFAULT_PROFILES_FILE is removed
from its environment). It writes when each request
came and when its image went, a JSON line each. Its `index` parameter picks the test object.

A run: the recognizer as users start it (the `recognizer` executable, its defaults but the
checkpoint, and its setup's parameters: `before`, as it was before it asked again for a late pose,
and `after`, its defaults now) in a process of its own, the camera in another, and an action client
here that sends one goal per seeded test object, each given --timeout seconds to answer (then
canceled). Per goal: answered or not, wall time, views, status; per view (the result's view_waits
and the camera's log): waiting for the image, the camera's latency (request stamp to its image
sent), waiting for the pose, computing, and the node's own waiting (the image wait less the
camera's latency, plus the pose wait).

    python benchmarks/driver_camera.py [--dataset procedural] [--episodes 40] [--seed 7]
        [--timeout 20] [--setups before after] [--orders pose_first pose_last]
        [--param NAME:=VALUE ...] [--out FILE]

Last line is JSON, also written to docs/results/driver_camera_procedural.json (modelnet:
docs/results/modelnet10/driver_camera_modelnet.json)."""
import argparse
import json
import os
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
from common import (
    add_common_flags, emit, one_line_errors, output, private_domain, results_dir, show_object, stop_processes)
from pose_wait import cpu, tail, waits_ms

CHECKPOINT = {"procedural": "procedural.pt", "modelnet": "modelnet10.pt"}
# recognizer parameters: as before the node asked again for a late pose (its reliable camera/pose
# then the same as image_qos auto's with a reliable camera), and its defaults now
SETUPS = {"before": ["pose_reask:=0.0", "image_qos:=reliable"], "after": []}
ORDERS = ("pose_first", "pose_last")  # the camera publishes each pose before its image, or after
DIAGNOSED = ("wait p", "asked again", "resent")  # /diagnostics keys kept: the waits' percentiles, re-asks
START_S = 180  # a process loading torch and a model beside others on a busy 2-core machine


def serve(args):
    """The driver camera node, spun until SIGTERM or Ctrl-C (the nodes' own run_node)."""
    from geometry_msgs.msg import PoseStamped
    from rcl_interfaces.msg import SetParametersResult
    from rclpy.node import Node
    from sensor_msgs.msg import CameraInfo, Image

    import msg_adapters as ma
    from active_recognition.nodes import run_node
    from active_recognition.simulation.depth_sensor import SimulatedCamera, sensor_config

    class DriverCamera(Node):
        def __init__(self):
            super().__init__("driver_camera")
            self.sim = SimulatedCamera(sensor_config("realsense"), args.seed)
            self.source = {"dataset": args.dataset, "split": "test", "root": args.root or ""}
            self.sim.load(index=self.declare_parameter("index", 0).value, **self.source)
            self.add_on_set_parameters_callback(self.on_parameters)
            self.pub_info = self.create_publisher(CameraInfo, "depth/camera_info", 10)
            self.pub_image = self.create_publisher(Image, "depth/image", 10)
            self.pub_pose = self.create_publisher(PoseStamped, "camera/pose", 10)
            self.create_subscription(PoseStamped, "next_view", self.on_view, 10)
            self.log = open(args.log, "a") if args.log else None

        def on_parameters(self, params):
            for p in params:
                if p.name == "index":
                    self.sim.load(index=int(p.value), **self.source)
            return SetParametersResult(successful=True)

        def on_view(self, msg):
            received = time.time()
            shot = self.sim.capture(*ma.pose_to_camera(msg))
            if shot is None:  # below the floor: a driver's arm does not get there
                return
            depth, position, rotation = shot
            stamp = msg.header.stamp
            pose = ma.position_to_pose(position, rotation, msg.header.frame_id, stamp)
            self.pub_info.publish(ma.camera_info(self.sim.k, stamp, "camera_depth_optical_frame"))
            if args.pose_first:
                self.pub_pose.publish(pose)
            self.pub_image.publish(ma.metres_to_image(depth, stamp, "camera_depth_optical_frame",
                                                      self.sim.sensor.encoding))
            if not args.pose_first:
                self.pub_pose.publish(pose)
            if self.log is not None:
                self.log.write(json.dumps({"stamp": ma.stamp_seconds(stamp), "received": received,
                                           "published": time.time()}) + "\n")
                self.log.flush()

    return run_node(DriverCamera, ["driver_camera"], "driver_camera")


def start(command, log, profile_free=False):
    """`command` in a process of its own, its output to the file `log` (its .log attribute)."""
    env = dict(os.environ)  # ROS_DOMAIN_ID and the discovery range
    if profile_free:  # Fast DDS as it comes
        for name in ("FASTRTPS_DEFAULT_PROFILES_FILE", "FASTDDS_DEFAULT_PROFILES_FILE", "FASTDDS_BUILTIN_TRANSPORTS"):
            env.pop(name, None)
    with open(log, "w") as out:
        proc = subprocess.Popen(command, env=env, stdout=out, stderr=subprocess.STDOUT)
    proc.log = log
    return proc


def objects(dataset, root, count, seed):
    """`count` test objects of `dataset`, a seeded draw: [(index, true class)]."""
    from active_recognition.datasets import default_cache_dir, open_dataset
    test = open_dataset(dataset, root, "test", cache_dir=default_cache_dir())
    order = np.random.default_rng(seed).choice(len(test), min(count, len(test)), replace=False)
    return [(int(i), test.classes[test.items[i][1]]) for i in order]


def ready(node, client, params):
    """The action server, the camera's parameters and recognition/result are there, and the
    recognizer hears depth/image reliably (`image_qos: auto` follows the camera within a second)."""
    from rclpy.qos import ReliabilityPolicy
    subs = node.get_subscriptions_info_by_topic("/depth/image")
    return client.server_is_ready() and params.services_are_ready() and \
        node.count_publishers("/recognition/result") > 0 and \
        any(s.qos_profile.reliability == ReliabilityPolicy.RELIABLE for s in subs)


def goals(shown, camera, recognizer, timeout):
    """One Recognize goal per object of `shown` through the camera process -> [goal rows]."""
    from rclpy.action import ActionClient
    from rclpy.parameter_client import AsyncParameterClient
    from diagnostic_msgs.msg import DiagnosticArray
    from std_msgs.msg import String

    import msg_adapters as ma
    from active_recognition.nodes.demo import ros_session, spin_until
    from active_recognition_interfaces.action import Recognize

    with ros_session(one_thread=True) as (ctx, executor):
        import rclpy
        node = rclpy.create_node("driver_camera_client", context=ctx)
        executor.add_node(node)
        results, diagnostics = [], {}
        node.create_subscription(String, "/recognition/result", lambda m: results.append(json.loads(m.data)), 10)
        node.create_subscription(DiagnosticArray, "/diagnostics", lambda m: diagnostics.update(
            {k: v for s in m.status if s.name.endswith("recognizer: recognition")
             for k, v in ma.status_values(s).items() if any(d in k for d in DIAGNOSED)}), 10)
        params = AsyncParameterClient(node, "/driver_camera")
        client = ActionClient(node, Recognize, "/recognize")

        def dead():
            return [p for p in (camera, recognizer) if p.poll() is not None]
        if not spin_until(executor, lambda: ready(node, client, params) or dead(), START_S) or dead():
            raise RuntimeError(f"the loop did not come up within {START_S} s\n{tail(camera)}\n{tail(recognizer)}")
        rows = []
        for index, truth in shown:
            if show_object(executor, params, index) is None:
                raise RuntimeError(f"the camera did not take object {index}\n{tail(camera)}")
            del results[:]
            began = time.monotonic()
            sent = client.send_goal_async(Recognize.Goal())
            if not spin_until(executor, sent.done, 10) or not sent.result().accepted:
                raise RuntimeError(f"goal on object {index} not accepted\n{tail(recognizer)}")
            answer = sent.result().get_result_async()
            answered = spin_until(executor, answer.done, timeout)
            wall = time.monotonic() - began
            if not answered:  # ended, so that the next goal is not rejected
                sent.result().cancel_goal_async()
                spin_until(executor, answer.done, 30)
            spin_until(executor, lambda: results, 2.0)  # recognition/result, another topic
            result = results[-1] if results else {}
            rows.append({"index": index, "truth": truth, "answered": answered, "wall_s": wall,
                         "status": result.get("status", "none") if answered else "unanswered",
                         "label": result.get("label", ""), "views": result.get("views", 0),
                         "view_waits": result.get("view_waits", [])})
            print(f"object {index:4d} {truth:<12} {rows[-1]['status']:<10} {rows[-1]['label']:<12} "
                  f"{rows[-1]['views']:2d} views {wall:6.2f} s", flush=True)
        spin_until(executor, lambda: False, 1.5)  # /diagnostics, at 1 Hz, after the last goal
        client.destroy()
        return rows, diagnostics


def figures(rows, camera_log):
    """The run's figures: goals answered, wall time, and per view where the time went (ms)."""
    sent = {}
    for line in Path(camera_log).read_text().splitlines():
        entry = json.loads(line)
        sent[round(entry["stamp"], 6)] = entry["published"] - entry["stamp"]
    views = [{**v, "camera": sent.get(round(v["stamp"], 6), np.nan)}
             for r in rows if r["answered"] for v in r["view_waits"]]
    part = {k: np.array([v[k] for v in views], float) for k in ("image", "pose", "compute", "camera")}
    own = part["image"] - np.nan_to_num(part["camera"]) + part["pose"]
    wall = np.array([r["wall_s"] for r in rows if r["answered"]], float)
    answered = [r for r in rows if r["answered"]]
    return {"goals": len(rows), "unanswered": sum(not r["answered"] for r in rows),
            "accuracy": float(np.mean([r["label"] == r["truth"] for r in rows])),
            "statuses": {s: sum(r["status"] == s for r in rows) for s in sorted({r["status"] for r in rows})},
            "goal_wall_s": {"p50": float(np.median(wall)), "p99": float(np.percentile(wall, 99)),
                            "max": float(wall.max())} if len(wall) else {},
            "views": len(views), "s_per_view": float(wall.sum() / max(sum(r["views"] for r in answered), 1)),
            "node_wait_ms": waits_ms(own), **{f"{k}_ms": waits_ms(v) for k, v in part.items()},
            "views_own_wait_over_500ms": int((own > 0.5).sum())}


def run(dataset, root, shown, seed, params, pose_first, timeout, logs):
    """The camera and the recognizer (its `params`, NAME:=VALUE) in processes of their own, one goal
    per object of `shown` -> (the goal rows, the figures, the last /diagnostics waits)."""
    logs = Path(logs)
    camera_log = logs / "camera.jsonl"
    camera_log.write_text("")
    recognizer_exe = shutil.which("recognizer") or str(Path(sys.executable).parent / "recognizer")
    params = [a for p in [f"checkpoint:={CHECKPOINT[dataset]}", *params] for a in ("-p", p)]
    camera = start([sys.executable, __file__, "--serve", *(["--pose-first"] if pose_first else []),
                    "--dataset", dataset, "--seed", str(seed), "--log", str(camera_log),
                    *(["--root", root] if root else [])], logs / "camera.log", profile_free=True)
    recognizer = start([recognizer_exe, "--ros-args", *params], logs / "recognizer.log")
    try:
        rows, diagnostics = goals(shown, camera, recognizer, timeout)
    finally:
        stop_processes([recognizer, camera])
    return rows, figures(rows, camera_log), diagnostics


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--dataset", default="procedural", choices=list(CHECKPOINT),
                    help="test objects shown (and the shipped model the recognizer loads)")
    add_common_flags(ap, "root")
    ap.add_argument("--episodes", type=int, default=40, help="test objects (a seeded draw), one goal each")
    ap.add_argument("--seed", type=int, default=7, help="the objects shown and the camera's noise")
    ap.add_argument("--timeout", type=float, default=20.0, help="seconds a goal may take to answer")
    ap.add_argument("--setups", nargs="+", default=list(SETUPS), choices=list(SETUPS),
                    help="the recognizer as before the late-pose re-ask, and as now")
    ap.add_argument("--orders", nargs="+", default=list(ORDERS), choices=ORDERS,
                    help="the camera's order: each pose before its image, or after it")
    ap.add_argument("--param", action="append", default=[], metavar="NAME:=VALUE",
                    help="a recognizer parameter besides the setup's (repeatable)")
    add_common_flags(ap, "out", out="the dataset's committed driver_camera_<dataset>.json")
    ap.add_argument("--serve", action="store_true", help=argparse.SUPPRESS)  # the camera process
    ap.add_argument("--pose-first", action="store_true", help=argparse.SUPPRESS)
    ap.add_argument("--log", default="", help=argparse.SUPPRESS)
    args = ap.parse_args(argv)
    if args.serve:
        return serve(args)
    if args.episodes < 1 or not args.timeout > 0:
        ap.error("--episodes must be at least 1 and --timeout more than 0")
    partial = [f for f, changed in (("--episodes", args.episodes != 40), ("--seed", args.seed != 7),
                                    ("--timeout", args.timeout != 20.0), ("--param", bool(args.param)),
                                    ("--setups", args.setups != list(SETUPS)),
                                    ("--orders", args.orders != list(ORDERS))) if changed]
    out = output(ap, args.out, results_dir(args.dataset) / f"driver_camera_{args.dataset}.json", partial)
    private_domain()
    os.environ.setdefault("ROS_AUTOMATIC_DISCOVERY_RANGE", "LOCALHOST")
    from active_recognition.evaluation.report import write_json

    with one_line_errors(ap):  # a root without the dataset, before any process starts
        shown = objects(args.dataset, args.root, args.episodes, args.seed)
    model, avx = cpu()
    result = {"cpu": model, "avx512f": "avx512f" in avx, "cpu_count": os.cpu_count(),
              "dataset": args.dataset, "episodes": len(shown), "seed": args.seed, "timeout_s": args.timeout,
              "camera": "driver_camera.py --serve: RealSense preset 640x480 16UC1, default QoS (reliable, "
                        "keep-last 10), Fast DDS defaults (no profile), info, then pose and image "
                        "in the run's order, all stamped like the request",
              "setups": {name: SETUPS[name] + args.param for name in args.setups}, "runs": {}}
    for order in args.orders:  # before and after, one after the other, on the same objects
        for name in args.setups:
            with tempfile.TemporaryDirectory(prefix="driver_camera_") as logs:
                load = os.getloadavg()[0]
                rows, figs, diagnostics = run(args.dataset, args.root, shown, args.seed,
                                              SETUPS[name] + args.param, order == "pose_first",
                                              args.timeout, logs)
            result["runs"][f"{name}/{order}"] = {"load_average_1min": [load, os.getloadavg()[0]], **figs,
                                                 "diagnostics": diagnostics, "goals_detail": rows}
            print(summary(f"{name}/{order}", figs), flush=True)
    if out:
        write_json(Path(out), result)
    emit({"runs": {k: {f: v[f] for f in ("unanswered", "s_per_view", "node_wait_ms")}
                   for k, v in result["runs"].items()}})


def summary(name, f):
    """One run's figures in a line."""
    w = f["node_wait_ms"]
    return (f"{name:>17}: {f['unanswered']} of {f['goals']} unanswered, {f['s_per_view']:.2f} s a view, "
            f"node's own wait p50 {w.get('p50', 0):.0f} ms p99 {w.get('p99', 0):.0f} ms, "
            f"{f['views_own_wait_over_500ms']} of {f['views']} views over 0.5 s")


if __name__ == "__main__":
    main()
