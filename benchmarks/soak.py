# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""A soak: the recognizer node and a realistic camera in processes of their own, GOALS goals in
a row through the `recognize` action, with faults on a seeded schedule:
- both cores busy with other work (tools/load.sh, unless --no-load);
- a tenth of the camera's requests never answered (a dropped frame: its `unanswered`);
- the camera's transform 0-300 ms late on TF (its `tf_delay`, drawn anew at each start);
- the camera process killed mid-episode and started again (every --kill-every goals);
- cancels after 0-2 feedbacks, and preemptions (a goal sent while another runs: the node runs
  `goal_policy: preempt`), each on a tenth of the goals.
The camera is the simulated one at 640x480 (the RealSense preset), reliable, Fast DDS defaults.

Figures: goals answered (a result within --goal-timeout), wall time per goal (p50, p99) and per
view, statuses by goal state, cancels that ended CANCELED of those whose goal had not already
ended, the node's memory (RSS), threads and open files at goal 1, 100, ... and the last, the
node's own /diagnostics at the end (its waits per view), and accuracy on the goals no fault
touched.

    python benchmarks/soak.py [--goals 1000] [--seed 0] [--no-load] [--out FILE]

Last line is JSON, also written to docs/results/soak.json (a full run) or --out."""
import argparse
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
from common import RESULTS, add_common_flags, emit, output, private_domain, show_object, stop_processes
from pose_wait import camera_params, cpu, objects, ros_args, tail

ROOT = Path(__file__).resolve().parents[1]
START_S = 180  # a process loading torch beside the load on a busy machine
FAULTS = ("none", "cancel", "preempt", "kill")


def schedule(goals, seed, kill_every):
    """[(fault, after how many feedbacks)] a goal: seeded; a kill every `kill_every` goals."""
    rng = np.random.default_rng(seed)
    out = []
    for i in range(goals):
        draw = rng.random()
        fault = "kill" if kill_every and i % kill_every == kill_every // 2 else \
            "cancel" if draw < 0.1 else "preempt" if draw < 0.2 else "none"
        out.append((fault, int(rng.integers(0, 3))))
    return out


def start(module, params, log):
    with open(log, "w") as out:
        proc = subprocess.Popen([sys.executable, "-m", module, "--ros-args", *ros_args(params)],
                                stdout=out, stderr=subprocess.STDOUT, env=dict(os.environ))
    proc.log = log
    return proc


def usage(pid):
    import psutil
    p = psutil.Process(pid)
    return {"rss_mb": p.memory_info().rss / 2 ** 20, "threads": p.num_threads(), "fds": p.num_fds()}


def best(classification):
    """The best-scored class of a result's Classification ("" where it has none), UNLABELED aside."""
    scored = [(r.score, r.class_id) for r in classification.results if r.class_id != "UNLABELED"]
    return max(scored)[1] if scored else ""


class Soak:
    """The client side: an action client and a parameter client of the camera, in one node."""

    def __init__(self, executor, node, camera_start):
        from rclpy.action import ActionClient
        from rclpy.parameter_client import AsyncParameterClient

        from active_recognition_interfaces.action import Recognize
        self.Recognize, self.executor, self.node = Recognize, executor, node
        self.client = ActionClient(node, Recognize, "recognize")
        self.params = AsyncParameterClient(node, "/simulated_camera")
        self.camera_start = camera_start

    def spin_until(self, cond, timeout):
        from active_recognition.nodes.demo import spin_until
        return spin_until(self.executor, cond, timeout)

    def show(self, index):
        if not self.spin_until(self.params.services_are_ready, START_S):  # a camera started again
            return False
        taken = show_object(self.executor, self.params, index)
        return taken is not None and all(r.successful for r in taken)

    def send(self, feedback):
        sent = self.client.send_goal_async(self.Recognize.Goal(), feedback_callback=feedback)
        self.spin_until(sent.done, 30)
        return sent.result() if sent.done() else None

    def goal(self, fault, after, timeout):
        """One goal with its fault: {status, state, wall_s, views, fault, cancel}."""
        fed, began, record = [], time.monotonic(), {"fault": fault}
        handle = self.send(lambda msg: fed.append(time.monotonic()))
        if handle is None or not handle.accepted:
            return {**record, "status": "not accepted", "state": "REJECTED", "wall_s": 0.0, "views": 0}
        result = handle.get_result_async()
        if fault != "none":
            self.spin_until(lambda: len(fed) > after or result.done(), timeout)
            if fault == "cancel" and not result.done():
                cancel = handle.cancel_goal_async()
                self.spin_until(cancel.done, 10)
                # accepted: the goal had not ended (a cancel of an ended goal is refused)
                record["cancel"] = "accepted" if cancel.done() and cancel.result().goals_canceling \
                    else "refused"
            elif fault == "preempt" and not result.done():
                record["preempted_by"] = self.send(lambda msg: None)
            elif fault == "kill" and not result.done():
                self.camera_start(kill=True)
        self.spin_until(result.done, timeout)
        if not result.done():
            return {**record, "status": "no result", "state": "UNANSWERED",
                    "wall_s": time.monotonic() - began, "views": len(fed)}
        if "preempted_by" in record:  # the goal that preempted it runs on: its answer awaited too
            other = record.pop("preempted_by")
            if other is not None and other.accepted:
                self.spin_until(other.get_result_async().done, timeout)
        from action_msgs.msg import GoalStatus
        states = {GoalStatus.STATUS_SUCCEEDED: "SUCCEEDED", GoalStatus.STATUS_CANCELED: "CANCELED",
                  GoalStatus.STATUS_ABORTED: "ABORTED"}
        r = result.result()
        return {**record, "status": r.result.status, "state": states.get(r.status, str(r.status)),
                "wall_s": time.monotonic() - began, "views": int(r.result.views),
                "label": best(r.result.classification)}


def figures(records, usage_at, diagnostics, shown):
    wall = np.array([r["wall_s"] for r in records])
    views = np.array([max(r["views"], 1) for r in records])
    canceled = [r for r in records if r.get("cancel") == "accepted"]
    whole = [(r, truth) for r, (_, truth) in zip(records, shown) if r["fault"] == "none"]
    by = {}
    for r in records:
        by.setdefault(r["state"], {}).setdefault(r["status"], 0)
        by[r["state"]][r["status"]] += 1
    return {"goals": len(records), "answered": sum(r["state"] != "UNANSWERED" for r in records),
            "goal_wall_s": {"p50": float(np.percentile(wall, 50)), "p99": float(np.percentile(wall, 99)),
                            "max": float(wall.max())},
            "wall_per_view_s": {"p50": float(np.percentile(wall / views, 50)),
                                "p99": float(np.percentile(wall / views, 99))},
            "states": by, "faults": {f: sum(r["fault"] == f for r in records) for f in FAULTS},
            "cancels_sent": sum("cancel" in r for r in records), "cancels_accepted": len(canceled),
            "cancels_accepted_canceled": sum(r["state"] == "CANCELED" for r in canceled),
            "whole_goals": len(whole),
            "accuracy_whole": float(np.mean([r.get("label") == t for r, t in whole])) if whole else None,
            "node_usage": usage_at, "node_diagnostics": diagnostics}


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--goals", type=int, default=1000, help="goals in a row")
    ap.add_argument("--seed", type=int, default=0, help="the objects, the faults, the delays")
    ap.add_argument("--kill-every", type=int, default=100, help="the camera killed once in this many goals")
    ap.add_argument("--goal-timeout", type=float, default=120.0, help="seconds a goal may take to answer")
    ap.add_argument("--no-load", action="store_true", help="no tools/load.sh beside it")
    add_common_flags(ap, "out", out="docs/results/soak.json")
    args = ap.parse_args(argv)
    if not 1 <= args.goals <= 100000:
        ap.error(f"--goals must be 1..100000, got {args.goals}")
    if args.kill_every < 0 or args.goal_timeout <= 0:
        ap.error("--kill-every must be >= 0 and --goal-timeout > 0")
    partial = [f for f, c in (("--goals", args.goals != 1000), ("--seed", args.seed != 0),
                              ("--no-load", args.no_load), ("--kill-every", args.kill_every != 100)) if c]
    out = output(ap, args.out, RESULTS / "soak.json", partial)
    private_domain()
    os.environ.setdefault("ROS_AUTOMATIC_DISCOVERY_RANGE", "LOCALHOST")
    from active_recognition.datasets import default_cache_dir, open_dataset
    from active_recognition.evaluation.report import write_json
    from active_recognition.model.checkpoint import shipped

    total = len(open_dataset("procedural", split="test", cache_dir=default_cache_dir()))
    drawn = objects(total, args.seed)
    shown = [drawn[i % total] for i in range(args.goals)]
    plan = schedule(args.goals, args.seed, args.kill_every)
    rng = np.random.default_rng(args.seed + 1)
    model, avx = cpu()
    with tempfile.TemporaryDirectory(prefix="soak_") as logs:
        procs = {"recognizer": start("active_recognition.nodes.recognizer", {
            "checkpoint": str(shipped("procedural")), "pose_source": "tf", "goal_policy": "preempt",
            "seed": args.seed}, Path(logs) / "recognizer.log")}
        if not args.no_load:
            procs["load"] = subprocess.Popen(["bash", str(ROOT / "tools" / "load.sh"), "--seconds",
                                              str(int(args.goals * 30 + 600))])
        delays = []

        def camera_start(kill=False):
            if kill:
                procs["camera"].kill()
                procs["camera"].wait()
            delays.append(float(rng.uniform(0.0, 0.3)))
            procs["camera"] = start("active_recognition.nodes.simulated_camera", camera_params(
                args.seed + len(delays), image_qos="reliable", publish_tf=True, publish_pose=False,
                unanswered=0.1, tf_delay=round(delays[-1], 3)), Path(logs) / f"camera{len(delays)}.log")
        camera_start()
        records, usage_at, diagnostics = [], {}, None
        import rclpy
        from rclpy.executors import SingleThreadedExecutor
        rclpy.init()
        try:
            node = rclpy.create_node("soak")
            executor = SingleThreadedExecutor()
            executor.add_node(node)
            soak = Soak(executor, node, camera_start)
            from diagnostic_msgs.msg import DiagnosticArray

            import msg_adapters as ma
            latest = {}
            node.create_subscription(DiagnosticArray, "/diagnostics", lambda msg: latest.update(
                {s.name: ma.status_values(s) for s in msg.status if "recognizer" in s.name}), 10)
            if not soak.spin_until(soak.client.server_is_ready, START_S):
                raise SystemExit(f"soak: no recognize server within {START_S} s\n{tail(procs['recognizer'])}")
            began = time.monotonic()
            for i, ((index, truth), (fault, after)) in enumerate(zip(shown, plan)):
                if not soak.show(index):
                    raise SystemExit(f"soak: the camera did not take object {index}\n{tail(procs['camera'])}")
                records.append({"index": index, **soak.goal(fault, after, args.goal_timeout)})
                if i + 1 in (1, 100) or (i + 1) % 100 == 0 or i + 1 == args.goals:
                    usage_at[i + 1] = usage(procs["recognizer"].pid)
                    print(f"goal {i + 1}: {records[-1]['state']} {records[-1]['status']}, "
                          f"{usage_at[i + 1]}", flush=True)
            seconds = time.monotonic() - began
            soak.spin_until(lambda: False, 2.0)  # the last /diagnostics (1 Hz)
            diagnostics = dict(latest)
        finally:
            rclpy.try_shutdown()
            stop_processes(list(procs.values()))
    result = {"cpu": model, "avx_flags": avx, "cpu_count": os.cpu_count(), "seed": args.seed,
              "load": not args.no_load, "camera": "simulated_camera in another process, RealSense preset "
              "640x480, reliable, Fast DDS defaults, TF 0-300 ms late, a tenth of requests unanswered",
              "tf_delays_s": delays, "seconds": seconds, **figures(records, usage_at, diagnostics, shown),
              "records": records}
    if out:
        write_json(Path(out), result)
    emit({k: v for k, v in result.items() if k != "records"})


if __name__ == "__main__":
    main()
