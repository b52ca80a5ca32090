# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""Where a driver's camera/pose is lost, and whether the subscriber's side can keep it.

A writer process publishes, --count times at 5 Hz, what a plain depth driver does: a CameraInfo,
a PoseStamped, then a 640x480 16UC1 Image, all stamped alike, with ROS's default QoS (reliable,
keep-last 10) and Fast DDS's defaults (no profile). A reader process in another process counts,
per image, whether its pose came. The reader is varied, each variant a fresh pair of processes:
- `no_image`: the writer sends no image (is it the frame beside the pose that loses it?);
- `best_effort` (the recognizer's camera/pose under image_qos auto), `best_effort_depth10`,
  `reliable_depth10` (a lost pose repaired by the writer: how late it comes);
- `own_participant`: camera/pose read in a second rclpy context (a participant of its own);
- `udp_only`: the reader offers only UDPv4 (FASTDDS_BUILTIN_TRANSPORTS);
- `big_receive_buffer`: the reader's UDP receive buffer 4 MB (a profile file on its side).

    python benchmarks/pose_loss.py [--count 100] [--variants ...] [--out FILE]

Last line is JSON, also written to docs/results/pose_loss.json (or --out)."""
import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
from common import RESULTS, add_common_flags, emit, output, private_domain
from pose_wait import cpu

VARIANTS = {"no_image": {}, "best_effort": {}, "best_effort_depth10": {}, "reliable_depth10": {},
            "own_participant": {}, "udp_only": {"FASTDDS_BUILTIN_TRANSPORTS": "UDPv4"},
            "big_receive_buffer": {}}
BIG_BUFFER = """<?xml version="1.0" encoding="UTF-8" ?>
<dds xmlns="http://www.eprosima.com/XMLSchemas/fastRTPS_Profiles"><profiles>
  <transport_descriptors><transport_descriptor><transport_id>udp_big</transport_id><type>UDPv4</type>
    <receiveBufferSize>4194304</receiveBufferSize></transport_descriptor></transport_descriptors>
  <participant profile_name="big" is_default_profile="true"><rtps>
    <userTransports><transport_id>udp_big</transport_id></userTransports>
    <useBuiltinTransports>false</useBuiltinTransports></rtps></participant>
</profiles></dds>
"""


def write(count, with_image):
    """The writer: info, pose, image at 5 Hz once a reader of each is matched."""
    import rclpy
    from geometry_msgs.msg import PoseStamped
    from sensor_msgs.msg import CameraInfo, Image
    rclpy.init()
    node = rclpy.create_node("pose_loss_writer")
    info, pose = node.create_publisher(CameraInfo, "info", 10), node.create_publisher(PoseStamped, "pose", 10)
    image = node.create_publisher(Image, "image", 10)
    while node.count_subscribers("pose") == 0 or node.count_subscribers("image") == 0:
        rclpy.spin_once(node, timeout_sec=0.1)
    time.sleep(1.0)  # the reader's other endpoints matched too
    frame = Image(height=480, width=640, encoding="16UC1", step=1280, data=bytes(640 * 480 * 2))
    for i in range(count):
        stamp = node.get_clock().now().to_msg()
        msg = CameraInfo()
        msg.header.stamp = stamp
        info.publish(msg)
        msg = PoseStamped()
        msg.header.stamp, msg.header.frame_id = stamp, "object"
        pose.publish(msg)
        frame.header.stamp = stamp
        if with_image:
            image.publish(frame)
        time.sleep(0.2)
    time.sleep(2.0)
    node.destroy_node()
    rclpy.shutdown()


def read(count, variant, quiet_s=4.0):
    """The reader: for each image (or each stamp, no_image), whether and when its pose came."""
    import rclpy
    from geometry_msgs.msg import PoseStamped
    from rclpy.executors import SingleThreadedExecutor
    from rclpy.qos import HistoryPolicy, QoSProfile, ReliabilityPolicy
    from sensor_msgs.msg import CameraInfo, Image
    rclpy.init()
    node = rclpy.create_node("pose_loss_reader")
    poses, images, infos = {}, {}, {}

    def key(msg):
        return msg.header.stamp.sec, msg.header.stamp.nanosec

    reliable = variant == "reliable_depth10"
    depth = 10 if variant.endswith("depth10") else 1
    qos = QoSProfile(depth=depth, history=HistoryPolicy.KEEP_LAST,
                     reliability=ReliabilityPolicy.RELIABLE if reliable else ReliabilityPolicy.BEST_EFFORT)
    executors = [SingleThreadedExecutor()]
    executors[0].add_node(node)
    pose_node = node
    if variant == "own_participant":
        context = rclpy.Context()
        rclpy.init(context=context)
        pose_node = rclpy.create_node("pose_loss_pose_reader", context=context)
        executors.append(SingleThreadedExecutor(context=context))
        executors[1].add_node(pose_node)
    pose_node.create_subscription(PoseStamped, "pose", lambda m: poses.setdefault(key(m), time.monotonic()), qos)
    node.create_subscription(Image, "image", lambda m: images.setdefault(key(m), time.monotonic()),
                             QoSProfile(depth=1, reliability=ReliabilityPolicy.RELIABLE))
    node.create_subscription(CameraInfo, "info", lambda m: infos.setdefault(key(m), time.monotonic()), 10)
    last = time.monotonic()
    while len(infos) < count and time.monotonic() - last < quiet_s:
        seen = len(infos) + len(images) + len(poses)
        for executor in executors:
            executor.spin_once(timeout_sec=0.02)
        if len(infos) + len(images) + len(poses) != seen:
            last = time.monotonic()
    for executor in executors:
        executor.spin_once(timeout_sec=0.5)  # a pose repaired last
    sent = images if variant != "no_image" else infos
    late = [poses[k] - sent[k] for k in sent if k in poses]
    order = sorted(sent)
    half = len(order) // 2
    counts = {"stamps": len(infos), "images": len(images), "poses": len(poses),
              "lost": sum(k not in poses for k in sent),
              "lost_second_half": sum(k not in poses for k in order[half:]),  # discovery long done
              "late_over_50ms": sum(x > 0.05 for x in late),
              "late_p99_ms": float(np.percentile(late, 99)) * 1e3 if late else None}
    print(json.dumps(counts), flush=True)


def run(variant, count, folder):
    env = {**os.environ, **VARIANTS[variant]}
    for name in ("FASTRTPS_DEFAULT_PROFILES_FILE", "FASTDDS_DEFAULT_PROFILES_FILE"):
        env.pop(name, None)
    reader_env = dict(env)
    if variant == "big_receive_buffer":
        profile = Path(folder) / "big_receive_buffer.xml"
        profile.write_text(BIG_BUFFER)
        reader_env["FASTRTPS_DEFAULT_PROFILES_FILE"] = str(profile)
    writer_env = {k: v for k, v in env.items() if k != "FASTDDS_BUILTIN_TRANSPORTS"}  # the writer as shipped
    reader = subprocess.Popen([sys.executable, __file__, "--role", "read", "--variant", variant, "--count",
                               str(count)], env=reader_env, stdout=subprocess.PIPE, text=True)
    writer = subprocess.run([sys.executable, __file__, "--role", "write", "--variant", variant, "--count",
                             str(count)], env=writer_env, capture_output=True, text=True, timeout=600)
    out, _ = reader.communicate(timeout=120)
    if writer.returncode or reader.returncode:
        raise SystemExit(f"pose_loss: {variant} failed:\n{writer.stderr[-2000:]}\n{out[-2000:]}")
    return json.loads(out.strip().splitlines()[-1])


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--count", type=int, default=100, help="frames the writer sends (5 Hz)")
    ap.add_argument("--variants", nargs="+", default=list(VARIANTS), choices=list(VARIANTS))
    add_common_flags(ap, "out", out="docs/results/pose_loss.json")
    ap.add_argument("--role", choices=("write", "read"), help=argparse.SUPPRESS)
    ap.add_argument("--variant", default="best_effort", help=argparse.SUPPRESS)
    args = ap.parse_args(argv)
    if not 1 <= args.count <= 10000:
        ap.error(f"--count must be 1..10000, got {args.count}")
    if args.role == "write":
        return write(args.count, args.variant != "no_image")
    if args.role == "read":
        return read(args.count, args.variant)
    partial = [f for f, c in (("--count", args.count != 100), ("--variants", args.variants != list(VARIANTS))) if c]
    out = output(ap, args.out, RESULTS / "pose_loss.json", partial)
    private_domain()
    os.environ.setdefault("ROS_AUTOMATIC_DISCOVERY_RANGE", "LOCALHOST")
    model, avx = cpu()
    runs = {}
    with tempfile.TemporaryDirectory(prefix="pose_loss_") as folder:
        for variant in args.variants:
            load = os.getloadavg()[0]
            runs[variant] = {**run(variant, args.count, folder), "load_average_1min": load}
            print(f"{variant:>20}: {runs[variant]}", flush=True)
    from active_recognition.evaluation.report import write_json
    result = {"cpu": model, "avx_flags": avx, "cpu_count": os.cpu_count(), "count": args.count,
              "writer": "info, pose, then a 640x480 16UC1 image at 5 Hz; default QoS; Fast DDS defaults",
              "runs": runs}
    if out:
        write_json(Path(out), result)
    emit(result)


if __name__ == "__main__":
    main()
