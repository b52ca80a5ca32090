# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""The simulated camera's frames (options/camera_params.CameraFrames): requests in the object frame or in a
world frame the object stands in, and the camera's optical frame broadcast on TF with each image,
as a robot's robot_state_publisher and camera driver would (tf2_ros' broadcasters; imported only
where TF is asked for)."""
import math

import numpy as np

import msg_adapters as ma
from active_recognition.argument_checks import InputError
from active_recognition.nodes.tf_poses import imported_tf2
from active_recognition.sensing import geometry
from active_recognition.sensing.meshes import yaw_matrix


def object_in_world(config):
    """(position (3,), rotation (3, 3)) of the object frame in the world frame."""
    return (np.array([config.object_x, config.object_y, config.object_z]),
            yaw_matrix(math.radians(config.object_yaw)).T)  # yaw_matrix turns row vectors


class CameraTf:
    def __init__(self, node, config, optical_frame):
        self.node, self.config, self.optical_frame = node, config, optical_frame
        self.world = object_in_world(config) if config.world_frame else None
        self.broadcaster = None
        if config.publish_tf or config.world_frame:
            tf2_ros = imported_tf2()
            self.broadcaster = tf2_ros.TransformBroadcaster(node)
            if self.world is not None:  # the object's place, once and for all (latched)
                self.static = tf2_ros.StaticTransformBroadcaster(node)
                self.static.sendTransform(ma.position_to_transform(
                    *self.world, config.world_frame, config.object_frame, node.get_clock().now().to_msg()))

    def in_object(self, msg):
        """(position, optical rotation) in the object frame of a requested PoseStamped."""
        position, rotation = ma.pose_to_camera(msg)
        frame = msg.header.frame_id
        if self.world is not None and frame == self.config.world_frame:
            return geometry.moved(position, rotation, geometry.inverse(self.world))
        if self.broadcaster is not None and frame != self.config.object_frame:
            raise InputError(f"frame {frame!r} is neither object_frame {self.config.object_frame!r} nor "
                             f"world_frame {self.config.world_frame!r}")
        return position, rotation

    def pose_frame(self, msg):
        """The frame camera/pose answers a request in: the object's for one in world."""
        world = self.world is not None and msg.header.frame_id == self.config.world_frame
        return self.config.object_frame if world else msg.header.frame_id

    def send(self, position, rotation, stamp):
        """Broadcast the optical frame where the camera went (in the object frame), stamped like
        its image, tf_delay seconds later if that is set."""
        if not self.config.publish_tf:
            return
        parent = self.config.object_frame
        if self.world is not None:
            (position, rotation), parent = geometry.moved(position, rotation, self.world), self.config.world_frame
        msg = ma.position_to_transform(position, rotation, parent, self.optical_frame, stamp)
        if self.config.tf_delay <= 0:
            return self.broadcaster.sendTransform(msg)
        timer = None

        def later():
            self.node.destroy_timer(timer)
            self.broadcaster.sendTransform(msg)
        timer = self.node.create_timer(self.config.tf_delay, later)
