# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""What the recognizer publishes, from the controller's commands: next_view, each classified
image (today's topics, the vision_msgs Classification with the image's header, the action's
feedback) and each episode's end (the JSON result, its Classification, the action's result);
the latched class names and LabelInfo; its /diagnostics status. Without vision_msgs its outputs
are off and the node says so once."""
import json
import time

from geometry_msgs.msg import PoseStamped
from rclpy.qos import QoSDurabilityPolicy, QoSProfile
from std_msgs.msg import Float32MultiArray, Header, String
from visualization_msgs.msg import MarkerArray

import msg_adapters as ma
from active_recognition.nodes.recorder import vision_topics
from active_recognition.runtime.controller_commands import AskView, End, Step
from active_recognition.runtime.health import Health

LATCHED = QoSProfile(depth=1, durability=QoSDurabilityPolicy.TRANSIENT_LOCAL)
INPUT_KEYS = ("depth/image", "depth/camera_info", "camera/pose", "pose_wait", "planning_frame")  # refusals


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
            node.refuse.once("vision_msgs", "vision_msgs outputs off (recognition/classification, recognition/"
                             f"result/classification, recognition/label_info): {ma.VISION_MSGS_MISSING}", warn=True)

    def destroy(self):
        for pub in self.pubs.values():
            self.node.destroy_lifecycle_publisher(pub)
        self.pubs = {}

    def latched(self):
        """The class names and LabelInfo, for subscribers that come late (once active)."""
        self.pubs["classes"].publish(String(data=json.dumps(self.classes)))
        if self.vision:
            self.pubs["recognition/label_info"].publish(ma.label_info(self.classes, self.threshold))

    def send(self, c):
        """Publish a command of the controller: AskView, Step or End."""
        if isinstance(c, AskView):
            self.pubs["view"].publish(self.node.tf.view(c))
        elif isinstance(c, Step):
            self.step(c)
        elif isinstance(c, End):
            if not c.replaced:  # as before the action: a reset replaces an episode silently
                self.end(c)
            self.node.action.ended(c)

    def step(self, c):
        """A classified image's probabilities, label, views so far, Classification, feedback."""
        node, ms = self.node, (time.perf_counter() - c.arrived) * 1e3
        node.step_ms.append(ms)
        node.loop.health.step(node.now(), ms)
        self.pubs["probabilities"].publish(ma.probabilities_to_msg(c.obs.probs))
        self.pubs["label"].publish(String(data=c.obs.label))
        self.pubs["markers"].publish(ma.view_markers(node.core.views_taken(), node.core.standoff(node.loop.k),
                                                     node.loop.frame))
        if self.vision:
            self.pubs["recognition/classification"].publish(ma.classification(c.obs.probs, self.classes,
                                                                              c.header))
        node.action.feedback(c)

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
                                      frame_id=end.frame)
        if end.obs.status == "recognized":
            return ma.classification(end.obs.probs, self.classes, header)
        if end.obs.probs is not None:
            return ma.unknown_classification(header, end.obs.probs, self.classes)
        return ma.unknown_classification(header)


def diagnostics(node, now):
    """The DiagnosticArray a Recognizer publishes on /diagnostics; `now` is its clock's seconds."""
    state, loop = node.state, node.loop
    if loop is not None:
        level, message, values = loop.report(now, state == "active", state)
    else:  # unconfigured: an error where configure failed
        health = Health()
        health.error = None if node.failure is None else str(node.failure)
        (level, message), values = health.level(now, 1.0, False, state), {}
    values = {"state": state, "model": node.model_file or "", "model loaded": node.core is not None,
              **({"classes": len(node.core.classes), "planner": node.core.planner} if node.core else {}),
              "image_qos": node.image_qos,
              **{f"{sub.topic} reliability": sub.reliability for sub in node.inputs}, **values}
    refused = node.refuse.counts
    values.update({f"refused {key}": refused.get(key, 0) for key in INPUT_KEYS})
    values.update({f"refused {key}": n for key, n in sorted(refused.items()) if key.startswith("parameter ")})
    status = ma.diagnostic_status(f"{node.get_fully_qualified_name().lstrip('/')}: recognition", level,
                                  message, values)
    return ma.diagnostic_array([status], node.get_clock().now().to_msg())
