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

"""recognizer: depth images in, class probabilities and the next view out (one object at a time).

Any depth camera: each image is paired with the latest CameraInfo and with the camera pose of
its stamp, and the core reprojects it into the model's own camera (reprojection.py). Every input
is checked on arrival (plausible.py) and a refused one never reaches the core; a request no
usable image answers is sent again, then its view is given up for another (the episode ends
`no_image` when none can be had); no exception escapes a callback.
"""
import json
import sys
import time
from collections import deque
from dataclasses import fields, replace
from typing import NamedTuple

import numpy as np
from geometry_msgs.msg import PoseStamped
from rcl_interfaces.msg import SetParametersResult
from rclpy.node import Node
from rclpy.qos import QoSDurabilityPolicy, QoSProfile
from sensor_msgs.msg import CameraInfo, Image
from std_msgs.msg import Float32MultiArray, String
from std_srvs.srv import Trigger
from visualization_msgs.msg import MarkerArray

import msg_adapters as ma
from active_recognition import plausible
from active_recognition.checkpoint import model_path
from active_recognition.geometry import Intrinsics
from active_recognition.node_params import NodeConfig, RecognizerParameters
from active_recognition.nodes import Throttled, check_parameter, declare_parameters, guarded, \
    run_node
from active_recognition.nodes.inputs import SensorSubscription
from active_recognition.nodes.recorder import Recorder
from active_recognition.options import parameters
from active_recognition.recognizer import ActiveRecognizer, SensingConfig
from active_recognition.validation import InputError, group

PARAMS = parameters(RecognizerParameters)  # name: options.Param (default, check, description)
CHECKS = {name: param.check for name, param in PARAMS.items()}
SENSING = tuple(f.name for f in fields(SensingConfig))
TIMING = tuple(f.name for f in fields(NodeConfig) if f.metadata["runtime"])
RUNTIME = tuple(name for name, param in PARAMS.items() if not param.read_only)  # the rest: once, at start
QOS_CHECK_S = 1.0  # how often `image_qos: auto` looks at the publishers again


class Recognizer(Node):
    def __init__(self, **kwargs):
        super().__init__("recognizer", **kwargs)
        p = declare_parameters(self, PARAMS)
        cfg = RecognizerParameters(**group(RecognizerParameters, p))
        self.frame_id, self.fresh_only = p["frame_id"], p["require_fresh_images"]
        for name in TIMING:
            setattr(self, name, p[name])
        self.sensing = cfg.sensing
        self.core = ActiveRecognizer(model_path(p["checkpoint"], "modelnet"),  # real objects
                                     cfg.episode, p["seed"], p["planner"], self.sensing, cfg.limits)
        self.refuse = Throttled(self.get_logger())
        self.add_on_set_parameters_callback(guarded(
            self, self.on_parameters,
            lambda params: SetParametersResult(successful=False, reason="internal error")))
        latched = QoSProfile(depth=1, durability=QoSDurabilityPolicy.TRANSIENT_LOCAL)
        self.pub_classes = self.create_publisher(String, "recognition/classes", latched)
        self.pub_probs = self.create_publisher(Float32MultiArray, "recognition/probabilities", 10)
        self.pub_label = self.create_publisher(String, "recognition/label", 10)
        self.pub_result = self.create_publisher(String, "recognition/result", 10)
        self.pub_view = self.create_publisher(PoseStamped, "next_view", 10)
        self.pub_markers = self.create_publisher(MarkerArray, "recognition/views", 10)
        # info and pose first: when all three are ready at once, the executor takes them in order
        self.inputs = [SensorSubscription(self, kind, topic, guarded(self, callback), p["image_qos"])
                       for kind, topic, callback in ((CameraInfo, "depth/camera_info", self.on_info),
                                                     (PoseStamped, "camera/pose", self.on_pose),
                                                     (Image, "depth/image", self.on_image))]
        self.create_service(Trigger, "~/reset", guarded(self, self.on_reset, self.reset_failed))
        self.create_timer(0.01, guarded(self, self.on_timer))
        self.recorder = Recorder(self, p["record"]) if p["record"] else None
        if self.recorder is not None:
            self.get_logger().info(f"recording the loop's topics to {self.recorder.path}")
        self.pub_classes.publish(String(data=json.dumps(self.core.classes)))
        self.received = self.processed = self.idle = self.stale = self.rejected = self.empty = 0
        self.resent = self.unreachable = 0
        self.waiting_since, self.tries, self.qos_checked = None, 0, time.monotonic()
        self.step_ms = deque(maxlen=10000)  # image in -> next view out, for benchmarks
        self.poses = deque(maxlen=200)  # (stamp seconds, position, optical rotation)
        self.intrinsics, self.pending, self.request_stamp, self.told = None, None, None, set()
        self.info_refused = None  # why the latest camera_info was refused, until one passes
        self.expect_poses = True  # until an image has waited in vain for its pose
        self.get_logger().info(f"recognizer ready: {len(self.core.classes)} classes, "
                               f"planner {self.core.planner}")

    def destroy_node(self):
        if self.recorder is not None:
            self.get_logger().info(f"recorded {sum(self.recorder.counts.values())} messages to "
                                   f"{self.recorder.close()}")
            self.recorder = None
        super().destroy_node()

    def once(self, key, text):
        if key not in self.told:
            self.told.add(key)
            self.get_logger().info(text)

    def on_parameters(self, params):
        values = {}
        try:
            for p in params:
                name = p.name  # each parameter's refusals are throttled apart: one hides no other
                values[name] = check_parameter(CHECKS, name, p.value)
            name = "sensing"
            sensing = replace(self.sensing, **{k: v for k, v in values.items() if k in SENSING})
        except InputError as e:
            self.refuse(f"parameter {name}", f"parameter refused: {e}")
            return SetParametersResult(successful=False, reason=str(e))
        self.sensing = sensing
        for name in TIMING:
            setattr(self, name, values.get(name, getattr(self, name)))
        return SetParametersResult(successful=True)

    def request_view(self, again=False):
        """Publish next_view: the core's next view, or (`again`) the same one once more."""
        position, rotation = self.core.requested_pose(self.intrinsics)
        msg = ma.position_to_pose(position, rotation, self.frame_id, self.get_clock().now().to_msg())
        if not again:  # an answer to any try of this view is fresh
            self.request_stamp, self.tries = (msg.header.stamp.sec, msg.header.stamp.nanosec), 0
        self.tries += 1
        self.waiting_since = time.monotonic()
        self.pub_view.publish(msg)

    def on_reset(self, request, response):
        self.core.reset(sensing=self.sensing)
        self.request_stamp, self.pending = None, None
        self.request_view()
        response.success, response.message = True, "new object; first view requested"
        return response

    def reset_failed(self, request, response):
        response.success, response.message = False, "reset failed (logged); try again"
        return response

    def reject(self, reason):
        self.rejected += 1
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
        except ValueError as e:
            return self.refuse("camera/pose", f"camera/pose refused: {e}")
        self.poses.append((seconds, position, rotation))
        self.expect_poses = True
        if self.pending is not None:
            pose = self.pose_at(self.pending.stamp)
            if pose is not None:
                self.process(self.pending.metres, self.pending.k, pose, self.pending.start)

    def on_timer(self):
        if time.monotonic() - self.qos_checked > QOS_CHECK_S:
            self.qos_checked = time.monotonic()
            for sub in self.inputs:
                sub.follow()
        if self.pending is not None and time.monotonic() - self.pending.since > self.pose_tolerance:
            pose = self.pose_at(self.pending.stamp, final=True)
            if not self.poses:
                self.expect_poses = False
                self.once("pose", "no camera/pose received: assuming each image is taken at the "
                                  "requested view")
            elif pose is None:
                self.refuse("pose_tolerance", f"no camera/pose within pose_tolerance "
                                              f"({self.pose_tolerance} s) of the image: assuming "
                                              f"the requested view")
            self.process(self.pending.metres, self.pending.k, pose, self.pending.start)
        self.check_timeout()

    def check_timeout(self):
        """Send a request no usable image answered within view_timeout again; after max_retries
        resends give its view up (the core picks another, or ends the episode: no_image)."""
        if self.waiting_since is None or self.pending is not None or self.core.done or \
                time.monotonic() - self.waiting_since < self.view_timeout:
            return
        view = "({:.0f}, {:.0f}) deg".format(*np.degrees(self.core.view))
        if self.tries <= self.max_retries:
            self.resent += 1
            self.refuse("view_timeout", f"no usable image for view {view} within view_timeout "
                                        f"({self.view_timeout:g} s): asking again (try "
                                        f"{self.tries + 1} of {self.max_retries + 1})")
            return self.request_view(again=True)
        self.unreachable += 1
        obs = self.core.view_unreachable()
        if obs.done:
            self.refuse("no_image", f"view {view} unreachable after {self.tries} tries: no view "
                                    f"can be had ({self.sensing.max_unreachable_views} "
                                    f"unreachable in a row, or none left); the episode ends "
                                    f"with no_image")
            return self.finish(obs)
        self.refuse("unreachable", f"view {view} unreachable after {self.tries} tries: asking "
                                   f"for " + "({:.0f}, {:.0f}) deg".format(*np.degrees(self.core.view))
                    + " instead")
        self.request_view()

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
        self.received += 1
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
            self.pending = PendingImage(seconds, metres, k, since, start)
            return
        self.process(metres, k, pose, start)

    def process(self, metres, k, pose, start):
        self.pending = None
        try:
            obs = self.core.observe(metres, k, *(pose or (None, None)))
        except ValueError as e:
            return self.reject(str(e))
        self.waiting_since = None  # answered
        if obs.status == "empty":
            self.empty += 1
            self.refuse("empty", f"no object in the image ({obs.object_fraction:.2%} of the "
                                 f"model's pixels): asking for the same view again")
            return self.request_view()
        if obs.status != "no_object":
            self.processed += 1
            if not obs.done:
                self.request_view()
            self.step_ms.append((time.perf_counter() - start) * 1e3)
            self.pub_probs.publish(ma.probabilities_to_msg(obs.probs))
            self.pub_label.publish(String(data=obs.label))
            self.pub_markers.publish(ma.view_markers(
                self.core.views_taken(), self.core.standoff(self.intrinsics), self.frame_id))
        if obs.done:
            self.finish(obs)

    def finish(self, obs):
        self.request_stamp, self.waiting_since = None, None
        self.pub_result.publish(String(data=json.dumps(obs.result())))


class PendingImage(NamedTuple):
    """An image waiting for the camera/pose of its stamp."""

    stamp: float           # seconds: the image's stamp
    metres: np.ndarray     # (H, W) depth, NaN = no return
    k: Intrinsics | None   # the image's camera; None: the model's own
    since: float           # time.monotonic() when the wait began (a newer image keeps it)
    start: float           # time.perf_counter() when the image arrived (the step's latency)


def main(args=None):
    return run_node(Recognizer, args)


if __name__ == "__main__":
    sys.exit(main())
