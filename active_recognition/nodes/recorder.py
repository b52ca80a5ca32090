# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""Record every topic of the loop to an MCAP file, as `ros2 bag record -s mcap` would.

Subscriptions take the serialized (CDR) bytes as they came over DDS; each channel carries its
type's complete ros2msg definition (msg_adapters.definitions), so rosbag2, Foxglove and the mcap
readers decode the file without this package. The file is written under a temporary name beside
the target and renamed into place when the recorder closes.
"""
import sys
import threading
import time
from collections import Counter
from contextlib import ExitStack
from functools import partial
from pathlib import Path

from geometry_msgs.msg import PoseStamped
from rclpy.callback_groups import MutuallyExclusiveCallbackGroup
from rclpy.qos import QoSDurabilityPolicy, QoSProfile, qos_profile_sensor_data
from sensor_msgs.msg import CameraInfo, Image
from std_msgs.msg import Float32MultiArray, String
from visualization_msgs.msg import MarkerArray

import msg_adapters as ma
from active_recognition.argument_checks import InputError
from active_recognition.atomic_files import atomic_write
from active_recognition.nodes import guarded
from msg_adapters.definitions import message_definition

RELIABLE = QoSProfile(depth=100)
LATCHED = QoSProfile(depth=1, durability=QoSDurabilityPolicy.TRANSIENT_LOCAL)
SENSOR = QoSProfile(depth=100, reliability=qos_profile_sensor_data.reliability)
TOPICS = {  # the loop's topics: (type, how to subscribe so that every publisher matches)
    "depth/image": (Image, SENSOR),
    "depth/camera_info": (CameraInfo, SENSOR),
    "camera/pose": (PoseStamped, SENSOR),
    "next_view": (PoseStamped, RELIABLE),
    "recognition/probabilities": (Float32MultiArray, RELIABLE),
    "recognition/label": (String, RELIABLE),
    "recognition/result": (String, RELIABLE),
    "recognition/views": (MarkerArray, RELIABLE),
    "recognition/classes": (String, LATCHED),
}


def vision_topics():
    """The recognizer's vision_msgs topics, as TOPICS gives the loop's; {} where vision_msgs
    cannot be used here (msg_adapters.HAVE_VISION_MSGS)."""
    if not ma.HAVE_VISION_MSGS:
        return {}
    from vision_msgs.msg import Classification, LabelInfo

    return {"recognition/classification": (Classification, RELIABLE),
            "recognition/result/classification": (Classification, RELIABLE),
            "recognition/label_info": (LabelInfo, LATCHED)}


def recorded_topics():
    """Every topic of the recognizer's loop, the vision_msgs ones where they can be had, and
    /diagnostics."""
    from diagnostic_msgs.msg import DiagnosticArray

    return {**TOPICS, **vision_topics(), "/diagnostics": (DiagnosticArray, RELIABLE)}


def type_name(kind):
    """sensor_msgs.msg.Image -> 'sensor_msgs/msg/Image'."""
    return f"{kind.__module__.split('.')[0]}/msg/{kind.__name__}"


def qos_metadata(qos):
    """The channel's offered_qos_profiles, in the YAML form rosbag2 (Jazzy) writes."""
    forever = "\n    sec: 9223372036\n    nsec: 854775807"  # RMW_DURATION_INFINITE
    return (f"- history: {qos.history.name.lower()}\n  depth: {qos.depth}\n"
            f"  reliability: {qos.reliability.name.lower()}\n"
            f"  durability: {qos.durability.name.lower()}\n"
            f"  deadline:{forever}\n  lifespan:{forever}\n"
            f"  liveliness: {qos.liveliness.name.lower()}\n"
            f"  liveliness_lease_duration:{forever}\n"
            "  avoid_ros_namespace_conventions: false")


def check_path(path):
    """The target as a Path, or an InputError that says what is wrong with it."""
    target = Path(path).expanduser()
    if target.suffix != ".mcap":
        raise InputError(f"record: {path!r} must be a file name ending in .mcap")
    if not target.parent.is_dir():
        raise InputError(f"record: {path!r}: folder {str(target.parent)!r} does not exist")
    if target.is_dir():
        raise InputError(f"record: {path!r} is a folder")
    return target


class Recorder:
    """Subscribes `node` to `topics` and writes what arrives to `path` until close()."""

    def __init__(self, node, path, topics=None):
        self.path = check_path(path)
        try:
            from mcap.writer import Writer
        except ImportError:
            raise InputError("record: needs the mcap package (pip install mcap, or rosdep install "
                             "with rosdep/active_recognition.yaml)") from None
        self.node, self.lock, self.counts = node, threading.Lock(), Counter()
        self.last = time.monotonic()  # when a message last arrived (quiet() reads it)
        self.output = ExitStack()  # the file under its temporary name until close()
        self.writer = Writer(self.output.enter_context(atomic_write(self.path, "wb")))
        self.writer.start(profile="ros2", library="active_recognition recorder")
        group = MutuallyExclusiveCallbackGroup()
        self.subscriptions, schemas = [], {}
        for topic, (kind, qos) in (topics or TOPICS).items():
            name = type_name(kind)
            if name not in schemas:
                schemas[name] = self.writer.register_schema(
                    name=name, encoding="ros2msg", data=message_definition(name).encode())
            full = node.resolve_topic_name(topic)
            channel = self.writer.register_channel(
                topic=full, message_encoding="cdr", schema_id=schemas[name],
                metadata={"offered_qos_profiles": qos_metadata(qos)})
            self.subscriptions.append(node.create_subscription(
                kind, topic, guarded(node, partial(self.on_message, full, channel)), qos, raw=True,
                callback_group=group))

    def ready(self):
        """Whether every topic has a publisher matched (the demo waits for this)."""
        return all(s.get_publisher_count() > 0 for s in self.subscriptions)

    def on_message(self, topic, channel, data):
        now = time.time_ns()
        with self.lock:
            if self.writer is None:
                return
            self.writer.add_message(channel_id=channel, log_time=now, data=data,
                                    publish_time=now, sequence=self.counts[topic])
            self.counts[topic] += 1
            self.last = time.monotonic()

    def quiet(self, seconds):
        """Whether nothing has arrived for `seconds`: what was published before has been written
        (a demo spins until this before it closes the file, so the last episode's end is in it)."""
        return time.monotonic() - self.last >= seconds

    def close_logged(self):
        """close(), and say so in the node's log (on stderr after Ctrl-C, when the context is
        shut down and rosout cannot take the line); returns None."""
        text = f"recorded {sum(self.counts.values())} messages to {self.close()}"
        if self.node.context.ok():
            self.node.get_logger().info(text)
        else:
            print(f"[{self.node.get_name()}]: {text}", file=sys.stderr)

    def close(self):
        """Finish the file and move it into place; returns its path."""
        with self.lock:
            if self.writer is None:
                return self.path
            for sub in self.subscriptions:
                self.node.destroy_subscription(sub)
            try:
                with self.output:  # closed and renamed into place; removed if finishing fails
                    self.writer.finish()
            finally:
                self.writer = None
        return self.path
