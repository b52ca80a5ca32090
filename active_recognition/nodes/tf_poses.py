# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""The recognizer's TF, where a robot keeps its frames (tf2_ros: no transform tree of our own).

With `pose_source: tf` each image's camera pose is the transform from the image's frame_id to
the episode's object frame at the image's stamp: an image waits for it up to pose_wait (the
controller's), and `poll` hands it over as soon as the buffer has it. With a `planning_frame`,
next_view goes out in that frame, through the latest transform from the object frame. Where
neither is asked for, tf2_ros is not needed and not imported.
"""
from geometry_msgs.msg import PoseStamped
from rclpy.time import Time

import msg_adapters as ma
from active_recognition.argument_checks import InputError
from active_recognition.sensing import geometry

HOW = ("bash tools/build_interfaces.sh builds it from ROS 2 Jazzy's geometry2 sources; on a ROS "
       "install it comes with rosdep (tf2_ros)")


def imported_tf2():
    """tf2_ros, or InputError saying how to get it."""
    try:
        import tf2_ros
    except ImportError as e:
        raise InputError(f"pose_source: tf and planning_frame need tf2_ros, which cannot be imported "
                         f"here ({e}): {HOW}") from e
    return tf2_ros


class TfPoses:
    def __init__(self, node, pose_source="topic", planning_frame=""):
        self.node, self.on, self.planning_frame = node, pose_source == "tf", planning_frame
        self.buffer = self.listener = None
        if self.on or planning_frame:
            tf2_ros = imported_tf2()
            self.buffer = tf2_ros.Buffer()
            self.listener = tf2_ros.TransformListener(self.buffer, node)

    def destroy(self):
        if self.listener is not None:
            self.listener.unregister()
            self.buffer = self.listener = None

    def lookup(self, target, source, stamp):
        """(position, rotation) of frame `source` in frame `target` at `stamp` (a Time message; zero:
        the latest), or the reason it cannot be had yet (a string)."""
        time = Time.from_msg(stamp)
        ok, why = self.buffer.can_transform_core(target, source, time)
        if not ok:
            return why or f"no transform from {source} to {target}"
        return ma.transform_to_camera(self.buffer.lookup_transform_core(target, source, time).transform)

    def poll(self, loop, now):
        """The controller's commands for the transform of the image it waits for, once TF has it
        (none before, or with pose_source: topic); the episode's end where TF has never had its
        object frame (controller.frame_missing)."""
        if not self.on or not loop.running:
            return []
        if not self.buffer._frameExists(loop.frame):  # tf2's BufferCore: a frame it has ever had
            return loop.frame_missing(now, f"TF has never had the object frame {loop.frame!r} (the goal's "
                                           f"object_frame, else parameter frame_id)")
        if loop.state != "classifying":
            return []
        header = loop.pending.header
        found = self.lookup(loop.frame, header.frame_id, header.stamp)
        if isinstance(found, str):  # why, for the refusal if it never comes
            loop.transform_missing(f"transform {header.frame_id} -> {loop.frame} ({' '.join(found.split())})")
            return []
        return loop.pose(now, loop.frame, ma.stamp_seconds(header.stamp), *found)

    def view(self, ask):
        """The next_view PoseStamped of a controller.AskView (None: an empty one), in the planning
        frame where one is set and TF has the transform from the object frame (else in the object
        frame, the refusal logged, named `planning_frame`)."""
        if ask is None:
            return PoseStamped()
        position, rotation, frame = ask.position, ask.rotation, ask.frame
        if self.planning_frame and frame != self.planning_frame:
            found = self.lookup(self.planning_frame, frame, Time().to_msg())  # the latest
            if isinstance(found, str):
                self.node.refuse("planning_frame", f"next_view: no transform from {frame} to planning_frame "
                                                   f"{self.planning_frame}: {found}")
            else:
                (position, rotation), frame = geometry.moved(position, rotation, found), self.planning_frame
        return ma.position_to_pose(position, rotation, frame, ma.seconds_to_stamp(ask.stamp))
