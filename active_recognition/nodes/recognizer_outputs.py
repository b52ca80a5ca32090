# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""What the recognizer publishes, from the controller's commands: next_view, each classified
image (today's topics, the vision_msgs Classification with the image's header, the action's
feedback) and each episode's end (the JSON result, its Classification, the action's result);
the latched class names and LabelInfo: from the command and what configure fixed alone.
Without vision_msgs its outputs are off and the node says so once."""
import json

from geometry_msgs.msg import PoseStamped
from rclpy.qos import QoSDurabilityPolicy, QoSProfile
from std_msgs.msg import Float32MultiArray, Header, String
from visualization_msgs.msg import MarkerArray

import msg_adapters as ma
from active_recognition.nodes.recorder import vision_topics
from active_recognition.runtime.controller_commands import AskView, End, Step

LATCHED = QoSProfile(depth=1, durability=QoSDurabilityPolicy.TRANSIENT_LOCAL)


class Outputs:
    """The recognizer's lifecycle publishers, made at configure: they send only while active.
    `view_msg`: an AskView's PoseStamped (TfPoses.view); `action` gets feedback and results."""

    def __init__(self, node, refuse, classes, threshold, view_msg, action):
        self.node, self.classes, self.threshold = node, list(classes), threshold
        self.view_msg, self.action = view_msg, action
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
            refuse.once("vision_msgs", "vision_msgs outputs off (recognition/classification, recognition/"
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
            self.pubs["view"].publish(self.view_msg(c))
        elif isinstance(c, Step):
            self.step(c)
        elif isinstance(c, End):
            if not c.replaced:  # as before the action: a reset replaces an episode silently
                self.end(c)
            if self.action.serves(c.goal):  # its result made now: a cleanup may free the outputs before it is sent
                self.action.ended(c.goal, c, self.verdict(c), self.verdict(c, canceled=True))

    def step(self, c):
        """A classified image's probabilities, label, views so far, Classification, feedback."""
        self.pubs["probabilities"].publish(ma.probabilities_to_msg(c.obs.probs))
        self.pubs["label"].publish(String(data=c.obs.label))
        self.pubs["markers"].publish(ma.view_markers(c.views, c.standoff, c.frame))
        serves = self.action.serves(c.goal)
        if self.vision or serves:
            classification = ma.classification(c.obs.probs, self.classes, c.header)
        if self.vision:
            self.pubs["recognition/classification"].publish(classification)
        if serves:
            self.action.feedback(c.goal, c, classification, self.view_msg(c.next_view))

    def end(self, end):
        """Publish the JSON result and the Classification of an episode that ended."""
        self.pubs["result"].publish(String(data=json.dumps(end.result)))
        if self.vision:
            self.pubs["recognition/result/classification"].publish(self.verdict(end))

    def verdict(self, end, canceled=False):
        """The Classification of an episode's end (`canceled`: had a cancel ended it): UNLABELED
        first unless an object was recognised, followed by the best guess so far; the last
        classified image's header, else now in the object frame."""
        header = end.header or Header(stamp=self.node.get_clock().now().to_msg(),
                                      frame_id=end.frame)
        if end.obs.status == "recognized" and not canceled:
            return ma.classification(end.obs.probs, self.classes, header)
        if end.obs.probs is not None:
            return ma.unknown_classification(header, end.obs.probs, self.classes)
        return ma.unknown_classification(header)
