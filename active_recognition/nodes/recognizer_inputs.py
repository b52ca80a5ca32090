# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""The recognizer's inputs (a mixin of nodes.recognizer.Recognizer): depth images, their
CameraInfo and the camera poses, each checked on arrival (plausible.py) and refused by name (a
refused one never reaches the core); an image is paired with the latest CameraInfo and with the
camera pose of its stamp, waiting up to pose_tolerance for a late pose.
"""
import time
from typing import NamedTuple

import numpy as np
from geometry_msgs.msg import PoseStamped
from sensor_msgs.msg import CameraInfo, Image
from std_msgs.msg import Header

import msg_adapters as ma
from active_recognition import plausible
from active_recognition.geometry import Intrinsics
from active_recognition.nodes import guarded
from active_recognition.nodes.inputs import SensorSubscription
from active_recognition.validation import InputError


class RecognizerInputs:
    """Opens and checks the inputs; a usable image goes to self.process (the node's)."""

    def open_inputs(self):
        # info and pose first: when all three are ready at once, the executor takes them in order
        self.inputs = [SensorSubscription(self, kind, topic, guarded(self, callback), self.image_qos)
                       for kind, topic, callback in ((CameraInfo, "depth/camera_info", self.on_info),
                                                     (PoseStamped, "camera/pose", self.on_pose),
                                                     (Image, "depth/image", self.on_image))]

    def close_inputs(self):
        for sub in self.inputs:
            self.destroy_subscription(sub.sub)
        self.inputs = []

    def reject(self, reason):
        self.rejected += 1
        self.health.refuse(time.monotonic())
        self.refuse("depth/image", f"depth image refused: {reason}")

    def now(self):
        return self.get_clock().now().nanoseconds * 1e-9

    def on_info(self, msg):
        try:
            k = plausible.check_intrinsics(ma.camera_info_to_intrinsics(msg))
        except ValueError as e:  # AdapterError, InputError
            # the camera is unknown again: images wait for a CameraInfo that passes, rather than
            # reach the model through the last one or a guess
            self.intrinsics, self.info_refused = None, str(e)
            return self.refuse("depth/camera_info", f"camera_info refused: {e}")
        self.intrinsics, self.info_refused = k, None

    def on_pose(self, msg):
        try:
            if msg.header.frame_id != self.frame_id:
                raise InputError(f"camera/pose header.frame_id {msg.header.frame_id!r} is not the "
                                 f"object frame {self.frame_id!r} (parameter frame_id)")
            seconds = plausible.check_clock(ma.stamp_seconds(msg.header.stamp), self.now(),
                                            self.max_clock_offset, "camera/pose")
            position, rotation = ma.pose_to_camera(msg)
            plausible.check_camera_position(position)
            size = self.core.sensing.object_size
            plausible.check_outside_box(position, self.core.centre * size, size)
        except ValueError as e:
            return self.refuse("camera/pose", f"camera/pose refused: {e}")
        self.poses.append((seconds, position, rotation))
        self.expect_poses = True
        if self.pending is not None:
            pose = self.pose_at(self.pending.stamp)
            if pose is not None:
                self.process_pending(pose)

    def pose_at(self, stamp, final=False):
        """(position, rotation) of the pose stamped like the image, else the nearest within
        pose_tolerance; None while none is that near. Until `final`, a pose stamped after
        the image must have arrived too (the image's own may still be on its way)."""
        best = min(self.poses, key=lambda p: abs(p[0] - stamp), default=None)
        if best is None or abs(best[0] - stamp) > self.pose_tolerance:
            return None
        if not final and best[0] != stamp and max(p[0] for p in self.poses) < stamp:
            return None
        return best[1:]

    def on_image(self, msg):
        start = time.perf_counter()
        if self.state != "active":
            return  # a frame already under way as the node deactivated
        self.received += 1
        self.health.frame(time.monotonic())
        if self.core.done:
            self.idle += 1
            return  # stopped: waiting for ~/reset
        stamp = (msg.header.stamp.sec, msg.header.stamp.nanosec)
        try:
            seconds = plausible.check_clock(ma.stamp_seconds(msg.header.stamp), self.now(),
                                            self.max_clock_offset)
        except InputError as e:
            return self.reject(str(e))
        if self.fresh_only and self.request_stamp is not None and stamp < self.request_stamp:
            self.stale += 1
            return  # taken before the camera reached the requested view
        try:
            metres = ma.image_to_metres(msg)
        except ma.AdapterError as e:
            return self.reject(str(e))
        k = self.intrinsics
        if k is None and self.info_refused:
            return self.reject(f"the latest camera_info was refused ({self.info_refused}): waiting for "
                               f"one that passes")
        if k is None:
            self.once("info", "no CameraInfo on depth/camera_info yet: assuming the model's own "
                              "camera (its field of view at the image's size)")
        elif (k.height, k.width) != metres.shape:
            return self.reject(f"image is {metres.shape[1]}x{metres.shape[0]} but the camera_info "
                               f"is for {k.width}x{k.height}")
        pose = self.pose_at(seconds)
        if pose is None and self.expect_poses:  # its pose may still be on its way
            # a newer image replaces the waiting one but not its wait: with no poses at all, a
            # 30 Hz camera would otherwise restart the wait forever
            since = self.pending.since if self.pending is not None else time.monotonic()
            self.pending = PendingImage(seconds, metres, k, since, start, msg.header)
            return
        self.process(metres, k, pose, start, msg.header)

    def process_pending(self, pose):
        p = self.pending
        self.process(p.metres, p.k, pose, p.start, p.header)


class PendingImage(NamedTuple):
    """An image waiting for the camera/pose of its stamp."""

    stamp: float           # seconds: the image's stamp
    metres: np.ndarray     # (H, W) depth, NaN = no return
    k: Intrinsics | None   # the image's camera; None: the model's own
    since: float           # time.monotonic() when the wait began (a newer image keeps it)
    start: float           # time.perf_counter() when the image arrived (the step's latency)
    header: Header         # the image's, for the Classification
