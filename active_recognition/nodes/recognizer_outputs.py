# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""What the recognizer publishes: its lifecycle publishers (today's topics and the vision_msgs
ones, where vision_msgs can be had) and its /diagnostics status.

The results go out twice: as before (probabilities, label, JSON result, latched class names) for
the users who have them, and as vision_msgs (a Classification per classified image with the
image's header, one at an episode's end, and the latched LabelInfo) for the tools of ROS's
perception convention. Where vision_msgs cannot be imported the vision outputs are off and the
node says so once.
"""
import json

from diagnostic_msgs.msg import DiagnosticArray
from geometry_msgs.msg import PoseStamped
from rclpy.qos import QoSDurabilityPolicy, QoSProfile
from std_msgs.msg import Float32MultiArray, Header, String
from visualization_msgs.msg import MarkerArray

import msg_adapters as ma
from active_recognition.controller import Timing
from active_recognition.health import Health
from active_recognition.nodes.recorder import RELIABLE, TOPICS, vision_topics

LATCHED = QoSProfile(depth=1, durability=QoSDurabilityPolicy.TRANSIENT_LOCAL)
VISION_TOPICS = ("recognition/classification", "recognition/result/classification",
                 "recognition/label_info")
INPUT_KEYS = ("depth/image", "depth/camera_info", "camera/pose", "pose_tolerance")  # refusals
IMAGE_COUNTS = ("received", "classified", "empty", "stale")


def recorded_topics():
    """Every topic of the loop, the vision_msgs ones where they can be had, and /diagnostics."""
    return {**TOPICS, **vision_topics(), "/diagnostics": (DiagnosticArray, RELIABLE)}


class Outputs:
    """The recognizer's lifecycle publishers, made at configure: they send only while active."""

    def __init__(self, node, classes, threshold):
        self.node, self.classes, self.threshold = node, list(classes), threshold
        make = node.create_lifecycle_publisher
        self.pubs = {"classes": make(String, "recognition/classes", LATCHED),
                     "probabilities": make(Float32MultiArray, "recognition/probabilities", 10),
                     "label": make(String, "recognition/label", 10),
                     "result": make(String, "recognition/result", 10),
                     "view": make(PoseStamped, "next_view", 10),
                     "markers": make(MarkerArray, "recognition/views", 10)}
        self.vision = ma.HAVE_VISION_MSGS
        if self.vision:
            for name, (kind, _) in vision_topics().items():
                self.pubs[name] = make(kind, name, LATCHED if name.endswith("label_info") else 10)
        else:
            node.once("vision_msgs", f"vision_msgs outputs off ({', '.join(VISION_TOPICS)}): "
                                     f"{ma.VISION_MSGS_MISSING}", warn=True)

    def destroy(self):
        for pub in self.pubs.values():
            self.node.destroy_lifecycle_publisher(pub)
        self.pubs = {}

    def latched(self):
        """The class names and LabelInfo, for subscribers that come late (once active)."""
        self.pubs["classes"].publish(String(data=json.dumps(self.classes)))
        if self.vision:
            self.pubs["recognition/label_info"].publish(ma.label_info(self.classes, self.threshold))

    def view(self, msg):
        self.pubs["view"].publish(msg)

    def step(self, obs, header, markers):
        """A classified image's probabilities, label, views so far and Classification."""
        self.pubs["probabilities"].publish(ma.probabilities_to_msg(obs.probs))
        self.pubs["label"].publish(String(data=obs.label))
        self.pubs["markers"].publish(markers)
        if self.vision:
            self.pubs["recognition/classification"].publish(
                ma.classification(obs.probs, self.classes, header))

    def end(self, end):
        """Publish the JSON result and the Classification of an episode that ended."""
        self.pubs["result"].publish(String(data=json.dumps(end.result)))
        if self.vision:
            self.pubs["recognition/result/classification"].publish(self.verdict(end))

    def verdict(self, end):
        """The Classification of an episode's end: UNLABELED first unless an object was
        recognised, followed by the best guess so far; the last classified image's header, else
        now in the object frame."""
        header = end.header or Header(stamp=self.node.get_clock().now().to_msg(),
                                      frame_id=self.node.loop.frame)
        if end.obs.status == "recognized":
            return ma.classification(end.obs.probs, self.classes, header)
        if end.obs.probs is not None:
            return ma.unknown_classification(header, end.obs.probs, self.classes)
        return ma.unknown_classification(header)


def diagnostics(node, now):
    """The DiagnosticArray a Recognizer publishes on /diagnostics; `now` is its clock's seconds."""
    loop, state = node.loop, node.state
    health = loop.health if loop is not None else Health()
    health.error = str(node.failure) if node.failure is not None else None
    timing = loop.timing if loop is not None else Timing()
    level, message = health.level(now, timing.view_timeout, state == "active", state)
    values = {"state": state, "model": node.model_file or "", "model loaded": node.core is not None}
    if node.core is not None:
        values.update({"classes": len(node.core.classes), "planner": node.core.planner})
    values["image_qos"] = node.image_qos
    values.update({f"{sub.topic} reliability": sub.reliability for sub in node.inputs})
    values.update(health.values(now))
    counts = loop.counts if loop is not None else {}
    values.update({f"images {key}": counts.get(key, 0) for key in IMAGE_COUNTS})
    values.update({"requests resent": counts.get("resent", 0),
                   "views unreachable": counts.get("unreachable", 0)})
    refused = node.refuse.counts
    values.update({f"refused {key}": refused.get(key, 0) for key in INPUT_KEYS})
    values.update({f"refused {key}": n for key, n in sorted(refused.items())
                   if key.startswith("parameter ")})
    values.update({"view_timeout (s)": timing.view_timeout,
                   "episode_timeout (s)": timing.episode_timeout})
    name = f"{node.get_fully_qualified_name().lstrip('/')}: recognition"
    status = ma.diagnostic_status(name, level, message, values)
    return ma.diagnostic_array([status], node.get_clock().now().to_msg())
