"""recognizer: depth images in, class probabilities and the next view out (one object at a time)."""
import json
import time
from collections import deque

from geometry_msgs.msg import PoseStamped
from rcl_interfaces.msg import ParameterType
from rclpy.node import Node
from rclpy.qos import QoSDurabilityPolicy, QoSProfile, qos_profile_sensor_data
from sensor_msgs.msg import Image
from std_msgs.msg import Float32MultiArray, String
from std_srvs.srv import Trigger
from visualization_msgs.msg import MarkerArray

import msg_adapters as ma
from active_recognition.nodes import declare_parameters, run_node
from active_recognition.episode import EpisodeConfig
from active_recognition.recognizer import ActiveRecognizer

PARAMS = {  # name: (default, type, description)
    "checkpoint": ("", ParameterType.PARAMETER_STRING, "model file; empty = the shipped model"),
    "planner": ("auto", ParameterType.PARAMETER_STRING,
                "next-view planner: auto (the checkpoint's best), learned, random, straight, "
                "reinforce, fixed or imitation"),
    "entropy_threshold": (0.1, ParameterType.PARAMETER_DOUBLE, "stop below this entropy (nats)"),
    "max_views": (10, ParameterType.PARAMETER_INTEGER, "stop after this many views"),
    "seed": (0, ParameterType.PARAMETER_INTEGER, "seed of the random initial views"),
    "frame_id": ("object", ParameterType.PARAMETER_STRING, "frame of next_view: the object's"),
    "require_fresh_images": (True, ParameterType.PARAMETER_BOOL,
                             "ignore images stamped before the last next_view request"),
}


class Recognizer(Node):
    def __init__(self, **kwargs):
        super().__init__("recognizer", **kwargs)
        p = declare_parameters(self, PARAMS)
        self.frame_id, self.fresh_only = p["frame_id"], p["require_fresh_images"]
        self.core = ActiveRecognizer(p["checkpoint"] or None,
                                     EpisodeConfig(p["max_views"], p["entropy_threshold"]), p["seed"],
                                     p["planner"])
        latched = QoSProfile(depth=1, durability=QoSDurabilityPolicy.TRANSIENT_LOCAL)
        self.pub_classes = self.create_publisher(String, "recognition/classes", latched)
        self.pub_probs = self.create_publisher(Float32MultiArray, "recognition/probabilities", 10)
        self.pub_label = self.create_publisher(String, "recognition/label", 10)
        self.pub_result = self.create_publisher(String, "recognition/result", 10)
        self.pub_view = self.create_publisher(PoseStamped, "next_view", 10)
        self.pub_markers = self.create_publisher(MarkerArray, "recognition/views", 10)
        self.create_subscription(Image, "depth/image", self.on_image, qos_profile_sensor_data)
        self.create_service(Trigger, "~/reset", self.on_reset)
        self.pub_classes.publish(String(data=json.dumps(self.core.classes)))
        self.received = self.processed = self.idle = self.stale = self.rejected = 0
        self.step_ms = deque(maxlen=10000)  # image in -> next view out, for benchmarks
        self.request_stamp = None
        self.get_logger().info(f"recognizer ready: {len(self.core.classes)} classes, "
                               f"planner {self.core.planner}")

    def request_view(self):
        msg = ma.view_to_pose(*self.core.view, self.core.radius, self.frame_id,
                              self.get_clock().now().to_msg())
        self.request_stamp = (msg.header.stamp.sec, msg.header.stamp.nanosec)
        self.pub_view.publish(msg)

    def on_reset(self, request, response):
        self.core.reset()
        self.request_stamp = None
        self.request_view()
        response.success, response.message = True, "new object; first view requested"
        return response

    def reject(self, reason):
        self.rejected += 1
        self.get_logger().warn(f"depth image rejected ({self.rejected} so far): {reason}",
                               throttle_duration_sec=2.0)

    def on_image(self, msg):
        start = time.perf_counter()
        self.received += 1
        if self.core.done:
            self.idle += 1
            return  # stopped: waiting for ~/reset
        stamp = (msg.header.stamp.sec, msg.header.stamp.nanosec)
        if self.fresh_only and self.request_stamp is not None and stamp < self.request_stamp:
            self.stale += 1
            return  # taken before the camera reached the requested view
        try:
            obs = self.core.observe(ma.image_to_metres(msg))
        except ma.AdapterError as e:
            return self.reject(str(e))
        self.processed += 1
        if obs.done:
            self.request_stamp = None
        else:
            self.request_view()
        self.step_ms.append((time.perf_counter() - start) * 1e3)
        self.pub_probs.publish(ma.probabilities_to_msg(obs.probs))
        self.pub_label.publish(String(data=obs.label))
        self.pub_markers.publish(ma.view_markers(self.core.views_taken(), self.core.radius,
                                                 self.frame_id))
        if obs.done:
            self.pub_result.publish(String(data=json.dumps(
                {"label": obs.label, "probability": float(obs.probs.max()),
                 "entropy": obs.entropy, "views": obs.views})))


def main(args=None):
    run_node(Recognizer, args)


if __name__ == "__main__":
    main()
