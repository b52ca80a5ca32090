# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""recognizer: depth images in, class probabilities and the next view out (one object at a time).

A managed (lifecycle) node: configure checks the parameters and loads the model, activate opens
the topics, deactivate pauses the episode, cleanup frees the model (`autostart`: active at
once). An episode starts with a `recognize` goal or ~/reset. Its loop, states and timing are
controller.Controller's: this node turns messages into its events and its commands into
messages. Health on /diagnostics at 1 Hz."""
import sys
import time
from collections import deque

from diagnostic_msgs.msg import DiagnosticArray
from rcl_interfaces.msg import SetParametersResult
from rclpy.lifecycle import LifecycleNode, TransitionCallbackReturn
from std_srvs.srv import Trigger

import msg_adapters as ma
from active_recognition.argument_checks import InputError, group
from active_recognition.model.checkpoint import model_path
from active_recognition.nodes import Throttled, check_parameter, declare_parameters, guarded, run_node
from active_recognition.nodes.inputs import CameraInputs
from active_recognition.nodes.recognize_server import RecognizeServer
from active_recognition.nodes.recognizer_outputs import Outputs
from active_recognition.nodes.recorder import Recorder, recorded_topics
from active_recognition.nodes.tf_poses import TfPoses
from active_recognition.options.flags_and_parameters import parameters
from active_recognition.options.recognizer_params import RecognizerParameters, changed, check_goal
from active_recognition.runtime.active_recognizer import ActiveRecognizer
from active_recognition.runtime.controller import Controller
from active_recognition.runtime.controller_commands import Refuse, Step
from active_recognition.runtime.health import unconfigured

PARAMS = parameters(RecognizerParameters)  # name: options.Param (default, check, description)
CHECKS = {name: param.check for name, param in PARAMS.items()}
INPUT_KEYS = ("depth/image", "depth/camera_info", "camera/pose", "pose_wait", "planning_frame")  # refusals
SUCCESS, FAILURE = TransitionCallbackReturn.SUCCESS, TransitionCallbackReturn.FAILURE


class Recognizer(LifecycleNode):
    def __init__(self, **kwargs):
        super().__init__("recognizer", **kwargs)
        try:  # declared now; checked by configure, where a bad one fails the transition
            declare_parameters(self, PARAMS)
        except InputError:
            pass
        # The node's own state, all of it (its lifecycle state is rclpy's: `state`):
        self.autostart = self.get_parameter("autostart").value
        self.image_qos = self.get_parameter("image_qos").value
        self.core = self.loop = self.tf = None  # the model, the episode loop on it, TF (configure)
        self.sensing = None               # sensing settings for the next episode
        self.goal_policy = "reject"       # a goal while another runs (configure)
        self.model_file = self.outputs = self.recorder = self.failure = None
        self.inputs, self.timer = [], None
        self.refuse = Throttled(self.get_logger())  # warnings per key; once() for information
        self.step_ms = deque(maxlen=10000)  # image in -> next view out, for benchmarks
        self.add_on_set_parameters_callback(guarded(self, self.on_parameters, lambda params: SetParametersResult(
            successful=False, reason="internal error")))
        self.create_service(Trigger, "~/reset", guarded(self, self.on_reset, self.reset_failed))
        # the `recognize` action (where it can be had)
        self.action = RecognizeServer(self, self.refuse, self.admit_goal, self.start_goal, self.cancel_goal)
        # not a lifecycle publisher: a manager sees why configure failed (ERROR) and an idle node
        self.pub_diagnostics = self.create_publisher(DiagnosticArray, "/diagnostics", 10)
        self.create_timer(1.0, guarded(self, lambda: self.pub_diagnostics.publish(self.diagnostics(self.now()))))
        if self.autostart and self.trigger_configure() != SUCCESS:
            raise self.failure  # run_node: one line, exit 2
        if self.autostart and self.trigger_activate() != SUCCESS:
            raise self.failure or RuntimeError("recognizer: activate failed (logged)")

    @property
    def state(self):
        """The lifecycle state's label: unconfigured, inactive, active, finalized, ..."""
        return self._state_machine.current_state[1]

    def now(self):
        return self.get_clock().now().nanoseconds * 1e-9

    def on_configure(self, state):
        """Check every parameter and load the model; a bad one fails the transition, logged."""
        try:
            p = {name: check_parameter(CHECKS, name, self.get_parameter(name).value) for name in PARAMS}
            cfg = RecognizerParameters(**group(RecognizerParameters, p))
            self.model_file = str(model_path(p["checkpoint"], "modelnet"))  # real objects
            self.core = ActiveRecognizer(self.model_file, cfg.episode, p["seed"], p["planner"],
                                         cfg.sensing, cfg.limits)
            self.tf = TfPoses(self, p["pose_source"], p["planning_frame"])
        except (InputError, OSError, ValueError, RuntimeError) as e:
            self.failure = e
            if not self.autostart:  # at autostart the exception says it (run_node: one line)
                self.get_logger().error(f"configure failed: {e}")
            return FAILURE
        self.sensing, self.goal_policy, self.failure = cfg.sensing, p["goal_policy"], None
        self.loop = Controller(self.core, cfg.timing, p["frame_id"], cfg.robot, p["pose_source"])
        # LabelInfo's threshold: the least top score a recognised class has (below it: unsure)
        self.outputs = Outputs(self, self.refuse, self.core.classes, self.core.confidence, self.tf.view, self.action)
        if p["record"]:
            self.recorder = Recorder(self, p["record"], recorded_topics())
            self.get_logger().info(f"recording the loop's topics to {self.recorder.path}")
        self.get_logger().info(f"configured: {self.model_file}")
        return SUCCESS

    def on_activate(self, state):
        """Open the inputs, send the latched outputs; an episode paused by deactivate goes on
        (its view asked for again, its time without the pause)."""
        super().on_activate(state)  # the lifecycle publishers send from here
        calls = (self.on_info, None if self.tf.on else self.on_pose, self.on_image)  # pose_source tf: TF's only
        self.inputs = CameraInputs(self, *(f and guarded(self, f) for f in calls), mode=self.image_qos)
        self.timer = self.create_timer(0.01, guarded(self, self.on_timer))
        self.outputs.latched()
        self.get_logger().info(f"recognizer ready: {len(self.core.classes)} classes, planner {self.core.planner}")
        self.apply(self.loop.resume(self.now()))
        return SUCCESS

    def on_deactivate(self, state):
        """Stop answering: inputs closed, no next_view; the episode waits for activate."""
        self.loop.pause(self.now())
        self.inputs.close()
        self.destroy_timer(self.timer)
        return super().on_deactivate(state)

    def on_cleanup(self, state):
        """End the episode under way (canceled), free the model and the outputs."""
        self.apply(self.loop.cancel(self.now()))
        self.close_recorder()
        self.outputs.destroy()
        self.tf.destroy()
        self.core = self.loop = self.outputs = self.model_file = self.tf = None
        return SUCCESS

    def on_shutdown(self, state):
        if self.state == "active":
            self.on_deactivate(state)
        return self.on_cleanup(state) if self.loop is not None else SUCCESS

    def diagnostics(self, now):
        """The DiagnosticArray of /diagnostics; `now` is the clock's seconds."""
        state, loop, failure = self.state, self.loop, self.failure
        level, message, values = loop.report(now, state == "active", state) if loop else unconfigured(failure, state)
        values = {"state": state, "model": self.model_file or "", "model loaded": self.core is not None,
                  **({"classes": len(self.core.classes), "planner": self.core.planner} if self.core else {}),
                  "image_qos": self.image_qos,
                  **{f"{sub.topic} reliability": sub.reliability for sub in self.inputs}, **values,
                  **self.refuse.values(INPUT_KEYS)}
        status = ma.diagnostic_status(f"{self.get_fully_qualified_name().lstrip('/')}: recognition", level,
                                      message, values)
        return ma.diagnostic_array([status], self.get_clock().now().to_msg())

    def close_recorder(self):
        if self.recorder is not None:
            self.recorder.close_logged()
            self.recorder = None

    def destroy_node(self):
        self.close_recorder()
        self.action.destroy()
        super().destroy_node()

    def on_parameters(self, params):
        """Runtime changes: sensing from the next episode on, timing at once (unconfigured:
        configure reads them). Each refusal is throttled apart: one hides no other."""
        values = {}
        try:
            for p in params:
                name, values[p.name] = p.name, check_parameter(CHECKS, p.name, p.value)
            name = "sensing"
            if self.loop is not None:
                self.sensing, *timing = changed(values, self.sensing, self.loop.timing, self.loop.cost)
                self.loop.retime(*timing)
        except InputError as e:
            self.refuse(f"parameter {name}", f"parameter refused: {e}")
            return SetParametersResult(successful=False, reason=str(e))
        return SetParametersResult(successful=True)

    # --- messages -> events ---------------------------------------------------------------

    def on_reset(self, request, response):
        if self.state != "active":
            response.success, response.message = False, f"{self.state}: activate me first"
            return response
        self.apply(self.loop.start(self.now(), sensing=self.sensing))
        response.success, response.message = True, "new object; first view requested"
        return response

    def reset_failed(self, request, response):
        response.success, response.message = False, "reset failed (logged); try again"
        return response

    def admit_goal(self, goal, busy):
        """Refuse (InputError) a goal the node cannot run now; `busy`: another goal runs."""
        if self.state != "active":
            first = "configure and activate" if self.state == "unconfigured" else "activate"
            raise InputError(f"the node is {self.state}: {first} it first")
        check_goal(goal.object_size, goal.max_views, goal.time_budget)
        if busy and self.goal_policy == "reject":
            raise InputError("another goal is running (goal_policy: reject)")

    def start_goal(self, key, goal):
        self.apply(self.loop.start(self.now(), key, goal.object_frame, goal.object_size, goal.max_views,
                                   self.sensing, goal.time_budget))

    def cancel_goal(self, key):
        if self.loop is not None and self.loop.goal == key:
            self.apply(self.loop.cancel(self.now()))

    def on_timer(self):
        if self.state != "active":
            return  # a tick already under way as the node deactivated
        self.inputs.follow()
        self.apply(self.tf.poll(self.loop, self.now()) + self.loop.tick(self.now(), self.inputs.pose_publishers > 0))

    def on_info(self, msg):
        try:
            k = ma.camera_info_to_intrinsics(msg)
        except ma.AdapterError as e:
            return self.apply(self.loop.info(self.now(), refused=str(e)))
        self.apply(self.loop.info(self.now(), k))

    def on_pose(self, msg):
        try:
            position, rotation = ma.pose_to_camera(msg)
        except ma.AdapterError as e:
            return self.refuse("camera/pose", f"camera/pose refused: {e}")
        self.apply(self.loop.pose(self.now(), msg.header.frame_id, ma.stamp_seconds(msg.header.stamp),
                                  position, rotation))

    def on_image(self, msg):
        arrived = time.perf_counter()
        if self.state != "active":
            return  # a frame already under way as the node deactivated
        try:
            metres, refused = ma.image_to_metres(msg), None
        except ma.AdapterError as e:
            metres, refused = None, str(e)
        self.apply(self.loop.image(self.now(), ma.stamp_seconds(msg.header.stamp), metres, msg.header,
                                   arrived, refused))
        self.apply(self.tf.poll(self.loop, self.now()))

    # --- commands -> messages -------------------------------------------------------------

    def apply(self, commands):
        for c in commands:
            if isinstance(c, Refuse):
                self.refuse(c.key, c.reason)
                continue
            if isinstance(c, Step):  # image in -> next view out (its AskView went first)
                self.step_ms.append((time.perf_counter() - c.arrived) * 1e3)
                self.loop.health.step(self.now(), self.step_ms[-1])
            self.outputs.send(c)  # AskView, Step, End
        if self.loop is not None:
            for key, text in self.loop.notes:
                self.refuse.once(key, text)
            self.loop.notes.clear()


def main(args=None):
    return run_node(Recognizer, args, "recognizer", PARAMS)


if __name__ == "__main__":
    sys.exit(main())
