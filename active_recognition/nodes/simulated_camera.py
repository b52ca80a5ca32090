"""simulated_camera: renders the depth image a camera would see at every requested pose."""
from geometry_msgs.msg import PoseStamped
from rcl_interfaces.msg import ParameterType, SetParametersResult
from rclpy.node import Node
from rclpy.qos import qos_profile_sensor_data
from sensor_msgs.msg import CameraInfo, Image

import msg_adapters as ma
from active_recognition.nodes import declare_parameters, run_node
from active_recognition.simulated_camera import SimulatedCamera, camera_config

STR, DBL = ParameterType.PARAMETER_STRING, ParameterType.PARAMETER_DOUBLE
INT = ParameterType.PARAMETER_INTEGER
PARAMS = {  # name: (default, type, description)
    "mesh": ("", STR, "mesh file to show; empty = an object of `dataset`"),
    "dataset": ("procedural", STR, "procedural, twins, modelnet, shapenet or folder"),
    "root": ("", STR, "dataset root (not for procedural)"),
    "split": ("test", STR, "train or test"),
    "index": (0, INT, "which object of the dataset split"),
    "width": (64, INT, "image width, pixels"),
    "height": (64, INT, "image height, pixels"),
    "fov_deg": (0.0, DBL, "horizontal field of view; 0 = holds the [-0.5, 0.5]^3 cube from radius"),
    "radius": (1.0, DBL, "viewing-sphere radius the default field of view is made for"),
    "frame_id": ("camera_depth_optical_frame", STR, "frame_id of the images"),
    "noise_std": (0.0, DBL, "depth noise, metres at 1 m (grows with depth squared)"),
    "dropout": (0.0, DBL, "fraction of pixels with no return"),
    "seed": (0, INT, "seed of the noise"),
}
OBJECT = ("mesh", "dataset", "root", "split", "index")


class SimulatedCameraNode(Node):
    def __init__(self, **kwargs):
        super().__init__("simulated_camera", **kwargs)
        p = declare_parameters(self, PARAMS)
        self.sim = SimulatedCamera(camera_config(p["width"], p["height"], p["fov_deg"], p["radius"]),
                                   p["noise_std"], p["dropout"], p["seed"])
        self.sim.load(**{k: p[k] for k in OBJECT})
        self.frame_id = p["frame_id"]
        self.add_on_set_parameters_callback(self.on_parameters)
        self.pub_image = self.create_publisher(Image, "depth/image", qos_profile_sensor_data)
        self.pub_info = self.create_publisher(CameraInfo, "depth/camera_info", qos_profile_sensor_data)
        self.create_subscription(PoseStamped, "next_view", self.on_pose, 10)
        self.get_logger().info(f"simulated camera showing {self.sim.description}")

    def on_parameters(self, params):
        changes = {p.name: p.value for p in params if p.name in OBJECT}
        if not changes:
            return SetParametersResult(successful=True)
        source = {k: self.get_parameter(k).value for k in OBJECT}
        try:
            self.sim.load(**{**source, **changes})
        except (ValueError, OSError) as e:
            self.get_logger().error(f"cannot load object, keeping {self.sim.description}: {e}")
            return SetParametersResult(successful=False, reason=str(e))
        self.get_logger().info(f"now showing {self.sim.description}")
        return SetParametersResult(successful=True)

    def on_pose(self, msg):
        try:
            position, rotation = ma.pose_to_camera(msg)
        except ma.AdapterError as e:
            self.get_logger().warn(f"pose rejected: {e}", throttle_duration_sec=2.0)
            return
        depth = self.sim.render(position, rotation)
        stamp = msg.header.stamp
        self.pub_info.publish(ma.camera_info(self.sim.config, stamp, self.frame_id))
        self.pub_image.publish(ma.metres_to_image(depth, stamp, self.frame_id))


def main(args=None):
    run_node(SimulatedCameraNode, args)


if __name__ == "__main__":
    main()
