# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""The recognizer's `recognize` action (active_recognition_interfaces/action/Recognize): a goal
starts an episode on the node's controller, feedback follows each classified image, the result
comes when it ends; a cancel ends it at once (canceled, the best guess so far). A goal that
comes while another runs is rejected or preempts it (parameter goal_policy). Goal states:
recognized and unknown succeed, canceled is canceled (aborted when preempted), the others
(unsure: stopped below LabelInfo's threshold, its best guess in the result; no_object, no_image,
no_frame, timeout) abort. Where the interface package cannot be imported the node
runs without the action and says so once.
"""
from rclpy.action import ActionServer, CancelResponse, GoalResponse
from rclpy.task import Future

import msg_adapters as ma
from active_recognition.controller import check_goal
from active_recognition.validation import InputError

try:
    from active_recognition_interfaces.action import Recognize
except ImportError as e:  # built by tools/build_interfaces.sh, or rosdep on a ROS install
    Recognize, MISSING = None, str(e)

SUCCEEDS = ("recognized", "unknown")


class RecognizeServer:
    def __init__(self, node):
        # running: goal id (bytes; the controller's goal) -> (its handle, a Future of its End)
        self.node, self.running, self.server = node, {}, None
        if Recognize is None:
            node.refuse.once("action", f"the recognize action is off: {MISSING} (bash "
                                       f"tools/build_interfaces.sh builds it)", warn=True)
            return
        self.server = ActionServer(node, Recognize, "recognize", self.execute,
                                   goal_callback=self.on_goal, cancel_callback=self.on_cancel)

    def destroy(self):
        if self.server is not None:
            self.server.destroy()
            self.server = None

    def on_goal(self, goal):
        """Accept a goal the node can run now; refuse the others, with the reason logged."""
        node = self.node
        try:
            if node.state != "active":
                first = "configure and activate" if node.state == "unconfigured" else "activate"
                raise InputError(f"the node is {node.state}: {first} it first")
            check_goal(goal.object_size, goal.max_views, goal.time_budget)
            if self.running and node.goal_policy == "reject":
                raise InputError("another goal is running (goal_policy: reject)")
        except InputError as e:  # goals are few: each refusal is logged
            node.refuse.always("recognize", f"recognize goal rejected: {e}")
            return GoalResponse.REJECT
        return GoalResponse.ACCEPT

    def on_cancel(self, handle):
        loop = self.node.loop
        if loop is not None and loop.goal == bytes(handle.goal_id.uuid):  # its episode runs
            self.node.apply(self.node.loop.cancel(self.node.now()))
        return CancelResponse.ACCEPT

    async def execute(self, handle):
        node, goal, key = self.node, handle.request, bytes(handle.goal_id.uuid)
        done = Future()
        self.running[key] = handle, done
        node.apply(node.loop.start(node.now(), key, goal.object_frame, goal.object_size,
                                   goal.max_views, node.sensing, goal.time_budget))
        result = await done
        if result.status in SUCCEEDS:
            handle.succeed()
        elif result.status == "canceled" and handle.is_cancel_requested:
            handle.canceled()
        else:
            handle.abort()
        return result

    def feedback(self, step):
        if step.goal in self.running:
            self.running[step.goal][0].publish_feedback(Recognize.Feedback(
                views=step.obs.views, classification=ma.classification(
                    step.obs.probs, self.node.core.classes, step.header),
                next_view=self.node.tf.view(step.next_view), travel=step.travel, elapsed=step.elapsed))

    def ended(self, end):
        _, done = self.running.pop(end.goal, (None, None))
        if done is not None:  # the result made now: a cleanup may free the outputs before it is sent
            done.set_result(Recognize.Result(
                status=end.result["status"], classification=self.node.outputs.verdict(end),
                views=end.result["views"], travel=end.result["travel"], elapsed=end.result["elapsed"],
                robot_seconds=end.result["robot_seconds"]))
