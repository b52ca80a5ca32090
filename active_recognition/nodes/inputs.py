# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""Sensor subscriptions that match their publishers' reliability (`image_qos: auto`).

Keep-last 1 (a slow step works on the newest message, not a backlog). A reliable subscription
cannot hear a best-effort publisher, and a best-effort one loses large frames that cross
processes in UDP fragments (FastDDS: any frame above its 512 kB shared-memory segment), so
`auto` does what rosbag2's recorder does: reliable when every publisher of the topic offers
reliable, best effort otherwise (or while there is none), and it subscribes again when the
publishers change (`follow`, called now and then). Under `auto`, camera/pose is best effort
whatever its publishers offer: a reliable pose lost beside a large frame comes again only at its
writer's next heartbeat (3 s with Fast DDS's defaults), and holds back every later pose until
then, where the recognizer asks for the view again at once (pose_reask) and takes the next.
"""
import time

from geometry_msgs.msg import PoseStamped
from rclpy.qos import HistoryPolicy, QoSProfile, ReliabilityPolicy
from sensor_msgs.msg import CameraInfo, Image

FOLLOW_S = 1.0  # how often `auto` looks at the publishers again


def sensor_qos(reliable):
    return QoSProfile(depth=1, history=HistoryPolicy.KEEP_LAST,
                      reliability=ReliabilityPolicy.RELIABLE if reliable
                      else ReliabilityPolicy.BEST_EFFORT)


def offered_reliable(node, topic):
    """True when every publisher of `topic` offers reliable, False when one does not, None when
    there is none."""
    infos = node.get_publishers_info_by_topic(topic)
    if not infos:
        return None
    return all(i.qos_profile.reliability == ReliabilityPolicy.RELIABLE for i in infos)


class SensorSubscription:
    """A keep-last-1 subscription with the reliability of `mode` (one of options.recognizer_params.QOS_MODES)."""

    def __init__(self, node, msg_type, topic, callback, mode="auto"):
        self.node, self.msg_type, self.callback, self.mode = node, msg_type, callback, mode
        self.reliable = mode == "reliable"
        self.sub = node.create_subscription(msg_type, topic, callback, sensor_qos(self.reliable))
        self.topic = self.sub.topic_name  # resolved: namespace and remapping applied
        self.follow()

    def follow(self):
        """In `auto` mode, subscribe again if the publishers now offer another reliability;
        True when it did."""
        if self.mode != "auto":
            return False
        offered = offered_reliable(self.node, self.topic)
        if offered is None or offered == self.reliable:
            return False
        self.node.destroy_subscription(self.sub)
        self.reliable = offered
        self.sub = self.node.create_subscription(self.msg_type, self.topic, self.callback,
                                                 sensor_qos(offered))
        self.node.get_logger().info(f"{self.topic}: its publishers offer "
                                    f"{'reliable' if offered else 'best effort'}; subscribed so")
        return True

    @property
    def reliability(self):
        return "reliable" if self.reliable else "best_effort"


class CameraInputs(list):
    """A depth camera's subscriptions: depth/camera_info, camera/pose (none where on_pose is
    None) and depth/image, in that order (when all are ready at once the executor takes them so:
    an image finds its K and pose), each calling its callback."""

    def __init__(self, node, on_info, on_pose, on_image, mode="auto"):
        pose_mode = "sensor_data" if mode == "auto" else mode  # driver_camera_procedural.json
        super().__init__(SensorSubscription(node, kind, topic, callback, m)
                         for kind, topic, callback, m in
                         ((CameraInfo, "depth/camera_info", on_info, mode),
                          (PoseStamped, "camera/pose", on_pose, pose_mode),
                          (Image, "depth/image", on_image, mode)) if callback is not None)
        self.node, self.followed = node, time.monotonic()
        self.pose_publishers = self.count_pose_publishers()

    def count_pose_publishers(self):
        """Publishers of camera/pose (0 where it is not subscribed: pose_source tf)."""
        return sum(self.node.count_publishers(sub.topic) for sub in self if sub.msg_type is PoseStamped)

    def follow(self):
        """Every FOLLOW_S at most: each subscription follows its publishers (SensorSubscription),
        and camera/pose's publishers are counted again."""
        if time.monotonic() - self.followed > FOLLOW_S:
            self.followed = time.monotonic()
            for sub in self:
                sub.follow()
            self.pose_publishers = self.count_pose_publishers()

    def close(self):
        for sub in self:
            self.node.destroy_subscription(sub.sub)
        self.clear()
