# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

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
from rcl_interfaces.msg import SetParametersResult
from rclpy.node import Node
from rclpy.qos import QoSProfile, ReliabilityPolicy, qos_profile_sensor_data
from sensor_msgs.msg import CameraInfo, Image

import msg_adapters as ma
from active_recognition.argument_checks import InputError, group
from active_recognition.nodes import Throttled, check_parameter, declare_parameters, guarded, \
    run_node
from active_recognition.nodes.camera_tf import CameraTf
from active_recognition.options.camera_params import ObjectSource, SimulatedCameraParameters
from active_recognition.options.flags_and_parameters import parameters
from active_recognition.simulation.depth_sensor import SimulatedCamera

PARAMS = parameters(SimulatedCameraParameters)  # name: options.Param (default, check, description)
CHECKS = {name: param.check for name, param in PARAMS.items()}
OBJECT = tuple(f.name for f in fields(ObjectSource))  # may change at run time


class SimulatedCameraNode(Node):
    def __init__(self, **kwargs):
        super().__init__("simulated_camera", **kwargs)
        p = declare_parameters(self, PARAMS)
        sensor = SimulatedCameraParameters(**group(SimulatedCameraParameters, p)).sensor
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
        self.frames = CameraTf(self, SimulatedCameraParameters(**group(SimulatedCameraParameters, p)).frames,
                               self.frame_id)
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
            position, rotation = self.frames.in_object(msg)
        except ValueError as e:  # AdapterError, InputError
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
        if self.frames.config.publish_pose:
            self.pub_pose.publish(ma.position_to_pose(position, rotation, self.frames.pose_frame(msg), stamp))
        self.frames.send(position, rotation, stamp)
        self.pub_image.publish(ma.metres_to_image(depth, stamp, self.frame_id, self.sim.sensor.encoding))


def main(args=None):
    return run_node(SimulatedCameraNode, args, "simulated_camera", PARAMS)


if __name__ == "__main__":
    sys.exit(main())
