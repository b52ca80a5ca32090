# Copyright 2026 active_recognition maintainers
#
# Licensed under the Apache License, Version 2.0 (the "License");
# you may not use this file except in compliance with the License.
# You may obtain a copy of the License at
#
#     http://www.apache.org/licenses/LICENSE-2.0
#
# Unless required by applicable law or agreed to in writing, software
# distributed under the License is distributed on an "AS IS" BASIS,
# WITHOUT WARRANTIES OR CONDITIONS OF ANY KIND, either express or implied.
# See the License for the specific language governing permissions and
# limitations under the License.

"""simulated_camera: renders the depth image a camera would see at every requested pose.

Publishes, with one stamp, the image, its CameraInfo and the pose the camera really reached
(`pose_error_deg`); for a pose the arm cannot reach (below the `floor`, or one of the
`unanswered` share) it publishes nothing, as a robot whose motion planner fails. The sensor
parameters default to the model's own virtual camera;
`demo --camera realsense` sets them to simulated_camera.PRESETS["realsense"].
"""
import sys
from dataclasses import fields

from geometry_msgs.msg import PoseStamped
from rcl_interfaces.msg import ParameterType, SetParametersResult
from rclpy.node import Node
from rclpy.qos import QoSProfile, ReliabilityPolicy, qos_profile_sensor_data
from sensor_msgs.msg import CameraInfo, Image

import msg_adapters as ma
from active_recognition.datasets import NAMES, SPLITS
from active_recognition.nodes import Throttled, check_parameter, declare_parameters, guarded, \
    run_node
from active_recognition.simulated_camera import SensorConfig, SimulatedCamera
from active_recognition.validation import Check, InputError, SEED_MAX, checks

STR, DBL = ParameterType.PARAMETER_STRING, ParameterType.PARAMETER_DOUBLE
INT, BOOL = ParameterType.PARAMETER_INTEGER, ParameterType.PARAMETER_BOOL
TYPES = {int: INT, float: DBL, str: STR, bool: BOOL}
SENSOR_TEXT = {
    "width": "image width, pixels", "height": "image height, pixels",
    "fov": "horizontal field of view, degrees (used unless fx > 0)",
    "fx": "focal length x, pixels; 0 = from fov", "fy": "focal length y, pixels; 0 = fx",
    "cx": "principal point x, pixels; 0 = the centre", "cy": "principal point y; 0 = the centre",
    "noise": "depth noise: none or kinect (sigma = 0.0012 + 0.0019 (z - 0.4)^2 m)",
    "noise_scale": "multiplies the noise's sigma", "dropout": "fraction of pixels lost at random",
    "edge_dropout": "degrees: drop flying pixels at depth jumps steeper than a surface this far "
                    "from face-on; 0 = off",
    "min_range": "metres; no return nearer", "max_range": "metres; no return farther; 0 = none",
    "encoding": "32FC1 (metres) or 16UC1 (millimetres)",
    "floor": "an opaque plane under the object; a pose below it gets no image",
    "pose_error_deg": "the arm misses each pose by this orbit; camera/pose says where it went",
    "unanswered": "share of requests the arm never reaches: nothing is published for them",
    "object_size": "metres: the mesh's longest bounding-box edge",
}
PARAMS = {  # name: (default, type, description)
    "mesh": ("", STR, "mesh file to show; empty = an object of `dataset`"),
    "dataset": ("procedural", STR, "procedural, twins, modelnet, shapenet or folder"),
    "root": ("", STR, "dataset root (not for procedural)"),
    "split": ("test", STR, "train, val, test or cross (a generated benchmark's held-out styles)"),
    "index": (0, INT, "which object of the dataset split"),
    "frame_id": ("camera_depth_optical_frame", STR, "frame_id of the images"),
    "seed": (0, INT, "seed of the noise, the pose error and the unanswered requests"),
    "image_qos": ("sensor_data", STR, "reliability of depth/image, depth/camera_info and "
                                      "camera/pose: sensor_data (best effort) or reliable"),
    **{f.name: (f.default, TYPES[type(f.default)], SENSOR_TEXT[f.name])
       for f in fields(SensorConfig)},
}
OBJECT = ("mesh", "dataset", "root", "split", "index")  # may change at run time
CHECKS = {**checks(SensorConfig), "mesh": Check(str), "dataset": Check(str, choices=NAMES),
          "root": Check(str), "split": Check(str, choices=SPLITS), "index": Check(int, lo=0),
          "frame_id": Check(str, length=(1, None)), "seed": Check(int, lo=0, hi=SEED_MAX),
          "image_qos": Check(str, choices=("sensor_data", "reliable"))}


class SimulatedCameraNode(Node):
    def __init__(self, **kwargs):
        super().__init__("simulated_camera", **kwargs)
        p = declare_parameters(self, PARAMS, CHECKS, OBJECT)
        sensor = SensorConfig(**{f.name: p[f.name] for f in fields(SensorConfig)})
        self.sim = SimulatedCamera(sensor, p["seed"])
        self.sim.load(**{k: p[k] for k in OBJECT})
        self.frame_id = p["frame_id"]
        self.add_on_set_parameters_callback(guarded(
            self, self.on_parameters,
            lambda params: SetParametersResult(successful=False, reason="internal error")))
        qos = qos_profile_sensor_data if p["image_qos"] == "sensor_data" else \
            QoSProfile(depth=5, reliability=ReliabilityPolicy.RELIABLE)
        self.pub_image = self.create_publisher(Image, "depth/image", qos)
        self.pub_info = self.create_publisher(CameraInfo, "depth/camera_info", qos)
        self.pub_pose = self.create_publisher(PoseStamped, "camera/pose", qos)
        self.create_subscription(PoseStamped, "next_view", guarded(self, self.on_pose), 10)
        self.warn, self.unanswered = Throttled(self.get_logger()), 0
        self.get_logger().info(f"simulated camera ({sensor.width}x{sensor.height}) showing "
                               f"{self.sim.description}")

    def on_parameters(self, params):
        source = {k: self.get_parameter(k).value for k in OBJECT}
        try:
            changes = {p.name: check_parameter(CHECKS, p.name, p.value) for p in params
                       if p.name in OBJECT}
            if not changes:
                return SetParametersResult(successful=True)
            self.sim.load(**{**source, **changes})
        except (InputError, OSError) as e:
            self.get_logger().error(f"cannot load object, keeping {self.sim.description}: {e}")
            return SetParametersResult(successful=False, reason=str(e))
        self.get_logger().info(f"now showing {self.sim.description}")
        return SetParametersResult(successful=True)

    def on_pose(self, msg):
        try:
            position, rotation = ma.pose_to_camera(msg)
        except ma.AdapterError as e:
            return self.warn("next_view", f"pose rejected: {e}")
        shot = self.sim.capture(position, rotation)
        if shot is None:
            self.unanswered += 1
            where = "below the floor" if not self.sim.reachable(position) else "unanswered share"
            return self.warn("unreachable", f"pose ({', '.join(f'{v:.2f}' for v in position)}) "
                                            f"not reached ({where}): no image")
        depth, position, rotation = shot
        stamp = msg.header.stamp
        self.pub_info.publish(ma.camera_info(self.sim.k, stamp, self.frame_id))
        self.pub_pose.publish(ma.position_to_pose(position, rotation, msg.header.frame_id, stamp))
        self.pub_image.publish(ma.metres_to_image(depth, stamp, self.frame_id, self.sim.sensor.encoding))


def main(args=None):
    return run_node(SimulatedCameraNode, args)


if __name__ == "__main__":
    sys.exit(main())
