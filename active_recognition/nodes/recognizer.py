# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""recognizer: depth images in, class probabilities and the next view out (one object at a time).

A managed (lifecycle) node: configure checks every parameter and loads the model, activate opens
its topics, deactivate stops answering, cleanup frees the model; `autostart` (default) goes to
active at once. Its health goes to /diagnostics at 1 Hz; every episode ends within
episode_timeout (status `timeout`).

Any depth camera: each image is paired with the latest CameraInfo and with the camera pose of
its stamp, and the core reprojects it into the model's own camera (reprojection.py). Every input
is checked on arrival (plausible.py) and a refused one never reaches the core; a request no
usable image answers is sent again, then its view is given up for another (the episode ends
`no_image` when none can be had); no exception escapes a callback.
"""
import sys
import time
from collections import deque
from dataclasses import fields, replace

import numpy as np
from diagnostic_msgs.msg import DiagnosticArray
from rcl_interfaces.msg import SetParametersResult
from rclpy.lifecycle import LifecycleNode, TransitionCallbackReturn
from std_srvs.srv import Trigger

import msg_adapters as ma
from active_recognition.checkpoint import model_path
from active_recognition.health import Health
from active_recognition.node_params import NodeConfig, RecognizerParameters
from active_recognition.nodes import Throttled, check_parameter, declare_parameters, guarded, \
    run_node
from active_recognition.nodes.recognizer_inputs import RecognizerInputs
from active_recognition.nodes.recognizer_outputs import Outputs, diagnostics, end_header, \
    recorded_topics
from active_recognition.nodes.recorder import Recorder
from active_recognition.options import parameters
from active_recognition.recognizer import ActiveRecognizer, SensingConfig, least_top_score
from active_recognition.validation import InputError, group

PARAMS = parameters(RecognizerParameters)  # name: options.Param (default, check, description)
CHECKS = {name: param.check for name, param in PARAMS.items()}
SENSING = tuple(f.name for f in fields(SensingConfig))
TIMING = tuple(f.name for f in fields(NodeConfig) if f.metadata["runtime"])
RUNTIME = tuple(name for name, param in PARAMS.items() if not param.read_only)  # the rest: once, at start
QOS_CHECK_S = 1.0  # how often `image_qos: auto` looks at the publishers again
DIAGNOSTICS_S = 1.0  # /diagnostics period
SUCCESS, FAILURE = TransitionCallbackReturn.SUCCESS, TransitionCallbackReturn.FAILURE


class Recognizer(RecognizerInputs, LifecycleNode):
    def __init__(self, **kwargs):
        super().__init__("recognizer", **kwargs)
        try:  # declared now; checked by configure, where a bad one fails the transition
            declare_parameters(self, PARAMS)
        except InputError:
            pass
        for name in TIMING + ("image_qos", "autostart"):
            setattr(self, name, self.get_parameter(name).value)
        self.state, self.core, self.model_file, self.outputs, self.recorder = \
            "unconfigured", None, None, None, None
        self.inputs, self.timer, self.failure, self.paused_at, self.told = [], None, None, None, set()
        self.refuse, self.health = Throttled(self.get_logger()), Health()
        self.received = self.processed = self.idle = self.stale = self.rejected = self.empty = 0
        self.resent = self.unreachable = 0
        self.step_ms = deque(maxlen=10000)  # image in -> next view out, for benchmarks
        self.add_on_set_parameters_callback(guarded(
            self, self.on_parameters,
            lambda params: SetParametersResult(successful=False, reason="internal error")))
        self.create_service(Trigger, "~/reset", guarded(self, self.on_reset, self.reset_failed))
        # not a lifecycle publisher: a manager sees why configure failed (ERROR) and an idle node
        self.pub_diagnostics = self.create_publisher(DiagnosticArray, "/diagnostics", 10)
        self.create_timer(DIAGNOSTICS_S, guarded(self, self.on_diagnostics))
        if self.autostart and self.trigger_configure() != SUCCESS:
            raise self.failure  # run_node: one line, exit 2
        if self.autostart and self.trigger_activate() != SUCCESS:
            raise self.failure or RuntimeError("recognizer: activate failed (logged)")

    def on_configure(self, state):
        """Check every parameter and load the model; a bad one fails the transition, logged."""
        try:
            self.configure()
        except (InputError, OSError, ValueError, RuntimeError) as e:
            self.failure, self.health.error = e, str(e)
            if not self.autostart:  # at autostart the exception says it (run_node: one line)
                self.get_logger().error(f"configure failed: {e}")
            return FAILURE
        self.failure = self.health.error = None
        self.state = "inactive"
        self.get_logger().info(f"configured: {self.model_file}")
        return SUCCESS

    def configure(self):
        p = {name: check_parameter(CHECKS, name, self.get_parameter(name).value) for name in PARAMS}
        cfg = RecognizerParameters(**group(RecognizerParameters, p))
        self.frame_id, self.fresh_only = p["frame_id"], p["require_fresh_images"]
        for name in TIMING:
            setattr(self, name, p[name])
        self.sensing = cfg.sensing
        self.model_file = str(model_path(p["checkpoint"], "modelnet"))  # real objects
        core = ActiveRecognizer(self.model_file, cfg.episode, p["seed"], p["planner"], self.sensing,
                                cfg.limits)
        self.core = core  # the LabelInfo threshold: the least top score a recognised class has
        self.outputs = Outputs(self, core.classes,
                               least_top_score(p["entropy_threshold"], len(core.classes)))
        if p["record"]:
            self.recorder = Recorder(self, p["record"], recorded_topics())
            self.get_logger().info(f"recording the loop's topics to {self.recorder.path}")
        self.waiting_since, self.tries, self.qos_checked = None, 0, time.monotonic()
        self.poses = deque(maxlen=200)  # (stamp seconds, position, optical rotation)
        self.intrinsics, self.pending, self.request_stamp = None, None, None
        self.info_refused = None  # why the latest camera_info was refused, until one passes
        self.expect_poses = True  # until an image has waited in vain for its pose
        self.episode_start, self.last_header = None, None

    def on_activate(self, state):
        """Open the inputs, send the latched outputs; an episode paused by deactivate goes on
        (its view asked for again, its time without the pause)."""
        super().on_activate(state)  # the lifecycle publishers send from here
        self.open_inputs()
        self.timer = self.create_timer(0.01, guarded(self, self.on_timer))
        self.outputs.latched()
        self.state = "active"
        self.get_logger().info(f"recognizer ready: {len(self.core.classes)} classes, "
                               f"planner {self.core.planner}")
        if self.paused_at is not None:
            paused, self.paused_at = time.monotonic() - self.paused_at, None
            self.health.resumed(paused)
            if self.episode_start is not None:
                self.episode_start += paused
                self.request_view()
        return SUCCESS

    def on_deactivate(self, state):
        """Stop answering: inputs closed, no next_view; the episode waits for activate."""
        self.state, self.paused_at, self.pending, self.waiting_since = \
            "inactive", time.monotonic(), None, None
        self.close_inputs()
        self.destroy_timer(self.timer)
        return super().on_deactivate(state)

    def on_cleanup(self, state):
        """Free the model and the outputs (configure loads them again)."""
        self.close_recorder()
        if self.outputs is not None:
            self.outputs.destroy()
        self.core = self.outputs = self.model_file = None
        self.state, self.paused_at = "unconfigured", None
        return SUCCESS

    def on_shutdown(self, state):
        if self.state == "active":
            self.on_deactivate(state)
        self.on_cleanup(state)
        self.state = "finalized"
        return SUCCESS

    def on_diagnostics(self):
        self.pub_diagnostics.publish(diagnostics(self, time.monotonic()))

    def close_recorder(self):
        if self.recorder is not None:
            text = f"recorded {sum(self.recorder.counts.values())} messages to {self.recorder.close()}"
            if self.context.ok():
                self.get_logger().info(text)
            else:  # after Ctrl-C the context is shut down: rosout cannot take the line, rcl says so
                print(f"[{self.get_name()}]: {text}", file=sys.stderr)
            self.recorder = None

    def destroy_node(self):
        self.close_recorder()
        super().destroy_node()

    def once(self, key, text, warn=False):
        if key not in self.told:
            self.told.add(key)
            (self.get_logger().warn if warn else self.get_logger().info)(text)

    def on_parameters(self, params):
        values = {}
        try:
            for p in params:
                name = p.name  # each parameter's refusals are throttled apart: one hides no other
                values[name] = check_parameter(CHECKS, name, p.value)
            if self.core is None:  # unconfigured: configure reads them
                return SetParametersResult(successful=True)
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
        self.outputs.view(msg)

    def on_reset(self, request, response):
        if self.state != "active":
            response.success, response.message = False, f"{self.state}: activate me first"
            return response
        self.core.reset(sensing=self.sensing)
        self.request_stamp, self.pending, self.last_header = None, None, None
        self.episode_start = time.monotonic()
        self.health.started(self.episode_start)
        self.request_view()
        response.success, response.message = True, "new object; first view requested"
        return response

    def reset_failed(self, request, response):
        response.success, response.message = False, "reset failed (logged); try again"
        return response

    def on_timer(self):
        if self.state != "active":
            return  # a tick already under way as the node deactivated
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
            self.process_pending(pose)
        if self.episode_start is not None and not self.core.done and \
                time.monotonic() - self.episode_start > self.episode_timeout:
            self.refuse("episode_timeout", f"the episode ran past episode_timeout "
                                           f"({self.episode_timeout:g} s) after "
                                           f"{self.core.episode.steps} views: it ends with timeout")
            self.pending = None
            return self.finish(self.core.time_out())
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

    def process(self, metres, k, pose, start, header):
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
            ms = (time.perf_counter() - start) * 1e3
            self.step_ms.append(ms)
            self.health.step(time.monotonic(), ms)
            self.last_header = header
            self.outputs.step(obs, header, ma.view_markers(
                self.core.views_taken(), self.core.standoff(self.intrinsics), self.frame_id))
        if obs.done:
            self.finish(obs)

    def finish(self, obs):
        self.request_stamp, self.waiting_since, self.episode_start = None, None, None
        self.health.ended(obs.status)
        self.outputs.end(obs, end_header(self, self.last_header))


def main(args=None):
    return run_node(Recognizer, args, "recognizer", PARAMS)


if __name__ == "__main__":
    sys.exit(main())
