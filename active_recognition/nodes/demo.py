# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""The closed-loop demo: recognizer + simulated camera in one process, over real topics."""
import json
import threading
import time
from contextlib import contextmanager
from dataclasses import asdict

import numpy as np
import rclpy
from rclpy import executors
from rclpy.node import Node
from rclpy.parameter import Parameter
from std_msgs.msg import String
from std_srvs.srv import Trigger

from active_recognition.argument_checks import InputError
from active_recognition.datasets import default_cache_dir, open_dataset
from active_recognition.model.checkpoint import load_model, model_path
from active_recognition.nodes.recognizer import Recognizer
from active_recognition.nodes.recorder import check_path
from active_recognition.nodes.simulated_camera import SimulatedCameraNode
from active_recognition.simulation.depth_sensor import sensor_config


class MultiThreadedExecutor(executors.MultiThreadedExecutor):
    """rclpy's MultiThreadedExecutor without Jazzy's re-queueing bug (ros2/rclpy#1452, fixed
    upstream in #1547, newer than the Jazzy wheels): a callback task still waiting in the thread
    pool was yielded and queued again on every spin, and the spinning thread kept the GIL, so the
    pool filled with duplicates and latency grew with every message. Here a task already queued
    is not queued again, and the spinning thread steps aside briefly so the pool can start it. A
    coroutine task (an action's execute) that awaits yields and is queued again once its run
    in the pool has finished."""

    def _spin_once_impl(self, timeout_sec=None, wait_condition=lambda: False):
        try:
            handler, _, _ = self.wait_for_ready_callbacks(timeout_sec, None, wait_condition)
        except (executors.ExternalShutdownException, executors.ShutdownException,
                executors.TimeoutException, executors.ConditionReachedException):
            return
        if any(handler is queued for queued, run in self._futures if not run.done()):
            time.sleep(0.0002)  # queued, not started yet: let a pool thread take the GIL
            return
        self._futures.append((handler, self._executor.submit(handler)))
        for queued, run in self._futures[:]:
            if run.done():
                self._futures.remove((queued, run))
                run.result()  # raise any exceptions
                if queued.done():
                    queued.result()


@contextmanager
def ros_session(args=None, one_thread=False):
    """A private rclpy context and a MultiThreadedExecutor (`one_thread`: a SingleThreadedExecutor,
    every callback in the spinning thread, as `rclpy.spin` runs a node in its own process); every
    node added is destroyed after."""
    ctx = rclpy.Context()
    rclpy.init(args=args, context=ctx)
    executor = (executors.SingleThreadedExecutor if one_thread else MultiThreadedExecutor)(context=ctx)
    try:
        yield ctx, executor
    finally:
        nodes = executor.get_nodes()  # before shutdown, which forgets them
        executor.shutdown()
        for node in nodes:
            node.destroy_node()
        rclpy.try_shutdown(context=ctx)


class DemoClient(Node):
    """Starts each episode through ~/reset and waits for recognition/result."""

    def __init__(self, **kwargs):
        super().__init__("demo", **kwargs)
        self.reset = self.create_client(Trigger, "recognizer/reset")
        self.result, self.arrived = None, threading.Event()
        self.result_topic = self.create_subscription(String, "recognition/result", self.on_result, 10).topic_name

    def on_result(self, msg):
        try:
            self.result = json.loads(msg.data)
        except ValueError:
            self.get_logger().warn(f"recognition/result is not JSON: {msg.data[:80]!r}")
            return
        self.arrived.set()


def spin_until(executor, done, timeout):
    deadline = time.monotonic() + timeout
    while not done() and time.monotonic() < deadline:
        executor.spin_once(timeout_sec=0.01)
    return done()


def recognize(executor, client, timeout=10.0):
    """One closed-loop episode; returns the recognizer's final result (dict) or None. Waits first (up
    to `timeout`) until recognition/result has a publisher: a result sent before discovery matched
    the subscription is lost (a recognizer just started on a loaded machine)."""
    spin_until(executor, lambda: client.count_publishers(client.result_topic) > 0, timeout)
    client.arrived.clear()
    future = client.reset.call_async(Trigger.Request())
    if not spin_until(executor, future.done, timeout) or not future.result().success:
        return None
    return client.result if spin_until(executor, client.arrived.is_set, timeout) else None


def run_demo(objects=10, seed=0, checkpoint="", args=None, out=print, planner="auto",
             dataset="procedural", camera="virtual", record="", time_budget=0.0):
    """Recognise `objects` test objects of an embedded dataset in turn (with that dataset's
    shipped model unless `checkpoint` names one) through a simulated `camera` ("virtual" or
    "realsense", simulated_camera.PRESETS), each within `time_budget` robot seconds (0: none),
    recording every topic to the .mcap file `record` if given; returns the summary dict."""
    if record:
        check_path(record)  # refused now, not once both nodes are up and the camera has logged
    test = open_dataset(dataset, split="test", cache_dir=default_cache_dir())
    if not 1 <= objects <= len(test):
        raise InputError(f"objects must be 1..{len(test)} ({dataset} test split), got {objects}")
    checkpoint = str(model_path(checkpoint, dataset))
    classes = load_model(checkpoint)[1]  # refused now if unfit, not inside the recognizer node
    if classes != list(test.classes):
        raise InputError(f"checkpoint {checkpoint}: its classes {classes} are not the {dataset} "
                         f"dataset's {list(test.classes)}")
    sensor = [Parameter(k, value=v) for k, v in asdict(sensor_config(camera)).items()]
    order = np.random.default_rng(seed).permutation(len(test))[:objects]
    with ros_session(args) as (ctx, executor):
        camera = SimulatedCameraNode(context=ctx, parameter_overrides=sensor + [
            Parameter("dataset", value=dataset), Parameter("index", value=int(order[0])),
            Parameter("seed", value=seed)])
        recognizer = Recognizer(context=ctx, parameter_overrides=[
            Parameter("checkpoint", value=checkpoint),
            Parameter("seed", value=seed), Parameter("planner", value=planner),
            Parameter("record", value=record), Parameter("time_budget", value=float(time_budget))])
        client = DemoClient(context=ctx)
        for node in (camera, recognizer, client):
            executor.add_node(node)
        if not spin_until(executor, client.reset.service_is_ready, 10.0):
            raise RuntimeError("the recognizer's reset service did not appear")
        recorder = recognizer.recorder
        if recorder is not None and not spin_until(executor, recorder.ready, 10.0):
            raise RuntimeError("the recorder's subscriptions found no publishers")
        rows, unsure = [], 0
        for n, index in enumerate(order):
            camera.set_parameters([Parameter("index", value=int(index))])
            truth = test.classes[test.items[index][1]]
            start = time.perf_counter()
            result = recognize(executor, client, timeout=30.0)  # no_image takes up to 12 s
            ms = (time.perf_counter() - start) * 1e3
            if result is None or result["status"] not in ("recognized", "unsure"):
                why = ("no result (timed out)" if result is None else
                       {"no_object": "no object seen",
                        "no_image": "no image came (no view could be had)",
                        "timeout": "the episode ran past episode_timeout",
                        "unknown": f"answered unknown (best guess {result.get('label') or 'none'})"}.get(
                           result["status"], f"ended {result['status']}"))
                out(f"object {n + 1}/{len(order)}: true={truth:<12} {why}")
                rows.append((False, 0, ms, float("nan")) if result is None else
                            (False, result["views"], ms, result["robot_seconds"]))
                continue
            ok = result["label"] == truth  # an unsure answer counts by its best guess, as before it had its status
            unsure += result["status"] == "unsure"
            rows.append((ok, result["views"], ms, result["robot_seconds"]))
            out(f"object {n + 1}/{len(order)}: true={truth:<12} predicted={result['label']:<12} "
                f"p={result['probability']:.2f}{' (unsure)' if result['status'] == 'unsure' else ''} "
                f"views={result['views']:<2} robot={result['robot_seconds']:.1f} s "
                f"time={ms:.0f} ms {'ok' if ok else 'WRONG'}")
        if recorder is not None:  # the last episode's end may still be on its way to the file
            spin_until(executor, lambda: recorder.quiet(0.25), 3.0)
        summary = {"objects": len(rows), "planner": recognizer.core.planner,
                   "camera": f"{camera.sim.sensor.width}x{camera.sim.sensor.height}",
                   "answered": sum(r[1] > 0 for r in rows),
                   "unsure": unsure,
                   "accuracy": float(np.mean([r[0] for r in rows])),
                   "mean_views": float(np.mean([r[1] for r in rows])),
                   "mean_robot_seconds": float(np.nanmean([r[3] for r in rows])) if any(
                       not np.isnan(r[3]) for r in rows) else float("nan"),
                   "ms_per_episode_p50": float(np.median([r[2] for r in rows])),
                   "rejected_images": recognizer.loop.counts["rejected"]}
        out(f"planner {recognizer.core.planner}: "
            f"accuracy {summary['accuracy']:.2f} over {summary['objects']} objects, "
            f"mean views {summary['mean_views']:.1f}, mean robot seconds {summary['mean_robot_seconds']:.1f}"
            + (f" (budget {time_budget:g} s)" if time_budget else "") + ", "
            f"median {summary['ms_per_episode_p50']:.0f} ms per episode")
    if recorder is not None:  # the session has closed it
        summary["recorded"] = dict(recorder.counts)
        out(f"recorded {sum(recorder.counts.values())} messages on {len(recorder.counts)} topics "
            f"to {recorder.path}")
    return summary
