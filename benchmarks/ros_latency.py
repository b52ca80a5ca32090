# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""ROS latency on this machine: the recognizer's step (image received -> next view published),
a full 10-view closed loop over topics with the simulated camera, at the model's own 64x64 and
at a RealSense's 640x480 and 1280x720 (the first view of each object included); a 30 Hz image
stream for 60 s (does it keep up, drop nothing it could process, keep its memory flat?); and a
30 Hz 640x480 stream with K and poses from another process, as a real camera's driver sends it.
Medians and p99; last line is JSON, also written to docs/results/ros_latency.json."""
import argparse
import json
import os
import resource
import subprocess
import sys
import time
from dataclasses import fields

import numpy as np
from common import RESULTS, emit, shipped_checkpoint
from geometry_msgs.msg import PoseStamped
from rclpy.node import Node
from rclpy.parameter import Parameter
from rclpy.qos import QoSProfile, ReliabilityPolicy, qos_profile_sensor_data
from sensor_msgs.msg import CameraInfo, Image

import msg_adapters as ma
from active_recognition.evaluation.report import write_json
from active_recognition.nodes.demo import DemoClient, recognize, ros_session, spin_until
from active_recognition.nodes.recognizer import Recognizer
from active_recognition.nodes.simulated_camera import SimulatedCameraNode
from active_recognition.sensing.reprojection import auto_standoff
from active_recognition.simulation.depth_sensor import sensor_config

# the RealSense preset (noise, holes, floor, 2 degrees of arm error) at two sizes
VGA = {"width": 640, "height": 480, "fx": 385.0, "fy": 385.0}
HD = {"width": 1280, "height": 720, "fx": 640.0, "fy": 640.0}
RELIABLE = QoSProfile(depth=1, reliability=ReliabilityPolicy.RELIABLE)
# the recognizer's default is the ModelNet10 model; these loops show procedural objects
PROCEDURAL = shipped_checkpoint()


def rss_mb():
    with open("/proc/self/statm") as f:
        return int(f.read().split()[1]) * resource.getpagesize() / 2 ** 20


def closed_loop(episodes, camera=None, pose_source="topic", checkpoint=None):
    """Time `episodes` 10-view episodes (after 2 to warm up) with the simulated camera, the
    model's own (camera None) or the RealSense preset with `camera`'s size and K, its pose on
    camera/pose or on TF (`pose_source`), the recognizer's model procedural.pt or `checkpoint`
    (a path; it classifies the same procedural objects). Every callback
    runs in one thread, as each node runs in its own process (`rclpy.spin`): in a multi-threaded
    executor's worker threads torch does not keep its one-thread setting, and a step of the
    compact model took 0.5 ms more."""
    with ros_session(one_thread=True) as (ctx, ex):
        sensor = [] if camera is None else [
            Parameter(f.name, value=getattr(sensor_config("realsense", **camera), f.name))
            for f in fields(sensor_config())]
        tf = pose_source == "tf"
        cam = SimulatedCameraNode(context=ctx, parameter_overrides=sensor + [
            Parameter("publish_tf", value=tf), Parameter("publish_pose", value=not tf)])
        model = PROCEDURAL if checkpoint is None else Parameter("checkpoint", value=str(checkpoint))
        rec = Recognizer(context=ctx, parameter_overrides=[model, Parameter("entropy_threshold", value=0.0),
                                                           Parameter("pose_source", value=pose_source)])
        client = DemoClient(context=ctx)
        for n in (cam, rec, client):
            ex.add_node(n)
        assert spin_until(ex, client.reset.service_is_ready, 10)
        times = []
        for i in range(episodes + 2):
            cam.set_parameters([Parameter("index", value=i * 7 % 500)])
            t = time.perf_counter()
            result = recognize(ex, client)
            assert result is not None and result["views"] == 10, result
            if i >= 2:
                times.append((time.perf_counter() - t) * 1e3)
            else:
                rec.step_ms.clear()  # warming up
        return times, np.array(rec.step_ms)


def stream(seconds, hz):
    with ros_session() as (ctx, ex):
        rec = Recognizer(context=ctx, parameter_overrides=[PROCEDURAL])
        client = DemoClient(context=ctx)
        sensor = Node("stream", context=ctx)
        pub = sensor.create_publisher(Image, "depth/image", qos_profile_sensor_data)
        for n in (rec, client, sensor):
            ex.add_node(n)
        assert spin_until(ex, lambda: pub.get_subscription_count() > 0, 10)
        cam = SimulatedCameraNode(context=ctx)  # only to render a realistic image
        depth = cam.sim.capture(*ma.pose_to_camera(ma.view_to_pose(1.0, 0.5)))[0]
        cam.destroy_node()
        published, rss, start = 0, [], time.monotonic()

        def tick():
            nonlocal published
            if not rec.loop.running and not client.reset_pending:
                client.reset_pending = True
                client.reset.call_async(rec_reset_request()).add_done_callback(
                    lambda f: setattr(client, "reset_pending", False))
            pub.publish(ma.metres_to_image(depth, sensor.get_clock().now().to_msg()))
            published += 1

        client.reset_pending = False
        sensor.create_timer(1.0 / hz, tick)
        while time.monotonic() - start < seconds:
            ex.spin_once(timeout_sec=0.01)
            if len(rss) < int(time.monotonic() - start):
                rss.append(rss_mb())
        spin_until(ex, lambda: False, 0.5)  # let the last images arrive
        n = rec.loop.counts
        lost = published - n["received"]
        could_process = n["received"] - n["idle"] - n["stale"] - n["rejected"]
        return {"stream_published": published, "stream_received": n["received"],
                "stream_processed": n["classified"], "stream_lost_in_transport": lost,
                "stream_unprocessed": could_process - n["classified"],
                "stream_idle_between_objects": n["idle"], "stream_stale": n["stale"],
                "rss_mb_at_10s": rss[9] if len(rss) > 9 else rss[-1], "rss_mb_at_end": rss[-1],
                "rss_growth_mb": rss[-1] - (rss[9] if len(rss) > 9 else rss[0])}


def publish_stream(seconds, hz, camera):
    """The camera's process (run as `--publish`): a RealSense frame, its CameraInfo and its pose
    at `hz` for `seconds`, reliable, once the recognizer subscribes. Prints what it sent, JSON."""
    import rclpy
    from active_recognition.simulation.depth_sensor import SimulatedCamera
    sensor = sensor_config("realsense", **camera)
    sim = SimulatedCamera(sensor)
    sim.load(dataset="procedural", split="test", index=3)
    rclpy.init()
    node = Node("camera_driver")
    pubs = [node.create_publisher(t, name, RELIABLE) for t, name in (
        (CameraInfo, "depth/camera_info"), (PoseStamped, "camera/pose"), (Image, "depth/image"))]
    deadline = time.monotonic() + 20
    while pubs[2].get_subscription_count() == 0 and time.monotonic() < deadline:
        rclpy.spin_once(node, timeout_sec=0.05)
    standoff = auto_standoff(sensor.intrinsics())
    pose = ma.pose_to_camera(ma.view_to_pose(1.0, 0.5, standoff))
    depth, position, rotation = sim.capture(*pose)
    image = ma.metres_to_image(depth, None, "camera", sensor.encoding)
    published, start = 0, time.monotonic()
    while time.monotonic() - start < seconds:
        stamp = node.get_clock().now().to_msg()
        image.header.stamp = stamp
        pubs[0].publish(ma.camera_info(sim.k, stamp, "camera"))
        pubs[1].publish(ma.position_to_pose(position, rotation, "object", stamp))
        pubs[2].publish(image)
        published += 1
        rclpy.spin_once(node, timeout_sec=max(0.0, start + published / hz - time.monotonic()))
    print(json.dumps({"published": published}), flush=True)
    node.destroy_node()
    rclpy.try_shutdown()


def vga_stream(seconds, hz):
    """The recognizer here, subscribing as it does; a 640x480 camera in another process."""
    driver = subprocess.Popen(
        [sys.executable, __file__, "--publish", str(seconds), "--hz", str(hz)],
        stdout=subprocess.PIPE, text=True, env=os.environ.copy())
    with ros_session() as (ctx, ex):
        rec = Recognizer(context=ctx, parameter_overrides=[PROCEDURAL])
        client = DemoClient(context=ctx)
        for n in (rec, client):
            ex.add_node(n)
        client.reset_pending = False
        while driver.poll() is None:
            ex.spin_once(timeout_sec=0.01)
            if not rec.loop.running and not client.reset_pending:
                client.reset_pending = True
                client.reset.call_async(rec_reset_request()).add_done_callback(
                    lambda f: setattr(client, "reset_pending", False))
        spin_until(ex, lambda: False, 0.5)  # let the last images arrive
        sent = json.loads(driver.stdout.read().strip().splitlines()[-1])["published"]
        n = rec.loop.counts
        return {"vga_stream_published": sent, "vga_stream_received": n["received"],
                "vga_stream_processed": n["classified"],
                "vga_stream_step_ms_p50": float(np.median(rec.step_ms)) if rec.step_ms else None}


def rec_reset_request():
    from std_srvs.srv import Trigger
    return Trigger.Request()


def main():
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--episodes", type=int, default=30)
    ap.add_argument("--seconds", type=float, default=60.0)
    ap.add_argument("--hz", type=float, default=30.0)
    ap.add_argument("--large-episodes", type=int, default=20,
                    help="episodes at 640x480 and at 1280x720")
    ap.add_argument("--publish", type=float, default=0.0,
                    help="(the camera's process) publish 640x480 frames for this many seconds")
    # --out by hand: a fixed default, written by every run (no partial-run guard)
    ap.add_argument("--out", default=str(RESULTS / "ros_latency.json"), help="JSON of the figures")
    args = ap.parse_args()
    if args.publish:
        return publish_stream(args.publish, args.hz, VGA)
    episodes, steps = closed_loop(args.episodes)
    out = {"step_ms_p50": float(np.percentile(steps, 50)), "step_ms_p99": float(np.percentile(steps, 99)),
           "episode_ms_p50": float(np.median(episodes)), "episode_ms_p99": float(np.percentile(episodes, 99)),
           "episodes": len(episodes)}
    print(f"step {out['step_ms_p50']:.2f} ms p50 / {out['step_ms_p99']:.2f} ms p99; "
          f"10-view episode {out['episode_ms_p50']:.1f} ms p50")
    for name, camera in (("vga", VGA), ("hd", HD)):
        _, large = closed_loop(args.large_episodes, camera)
        out[f"{name}_step_ms_p50"] = float(np.percentile(large, 50))
        out[f"{name}_step_ms_p99"] = float(np.percentile(large, 99))
        print(f"{camera['width']}x{camera['height']} step {out[name + '_step_ms_p50']:.2f} ms "
              f"p50 / {out[name + '_step_ms_p99']:.2f} ms p99 ({len(large)} steps)")
    out.update(stream(args.seconds, args.hz))
    print(f"{args.hz:.0f} Hz for {args.seconds:.0f} s: published {out['stream_published']}, "
          f"processed {out['stream_processed']}, unprocessed {out['stream_unprocessed']}, "
          f"rss growth {out['rss_growth_mb']:.1f} MB")
    out.update(vga_stream(args.seconds, args.hz))
    print(f"640x480 at {args.hz:.0f} Hz from another process (reliable publisher): published "
          f"{out['vga_stream_published']}, received {out['vga_stream_received']}, processed "
          f"{out['vga_stream_processed']}")
    write_json(args.out, out)
    emit(out)


if __name__ == "__main__":
    main()
