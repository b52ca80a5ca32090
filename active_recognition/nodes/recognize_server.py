# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""The recognizer's `recognize` action (active_recognition_interfaces/action/Recognize): a goal
starts an episode on the node's controller, feedback follows each classified image, the result
comes when it ends; a cancel ends it at once (canceled, the best guess so far), and a cancel
accepted after its episode ended but before its result was sent ends it canceled too. A goal that
comes while another runs is rejected or preempts it (parameter goal_policy). Goal states:
recognized and unknown succeed, canceled is canceled (aborted when preempted), the others
(unsure: stopped below LabelInfo's threshold, its best guess in the result; no_object, no_image,
no_frame, timeout) abort. Where the interface package cannot be imported the node
runs without the action and says so once.
"""
from dataclasses import replace

from rclpy.action import ActionServer, CancelResponse, GoalResponse
from rclpy.task import Future

import msg_adapters as ma
from active_recognition.argument_checks import InputError
from active_recognition.nodes import guarded
from active_recognition.runtime.controller import check_goal

try:
    from active_recognition_interfaces.action import Recognize
except ImportError as e:  # built by tools/build_interfaces.sh, or rosdep on a ROS install
    Recognize, MISSING = None, str(e)

SUCCEEDS = ("recognized", "unknown")


class RecognizeServer:
    """Every goal's state is decided in the node's callbacks (one mutually exclusive group): a
    goal is accepted and its episode started, canceled, ended and settled there, never in its
    execute coroutine, which only waits for its result. rclpy marks a goal canceling after
    on_cancel returns, so an end is settled by a callback of its own (`wake`), which runs after
    that: a cancel accepted before a goal's result is sent ends it CANCELED, whatever ended
    its episode."""

    def __init__(self, node):
        # running: goal id (bytes; the controller's goal) -> its handle, until its result is sent
        # results: goal id -> a Future of its Result (execute waits on it)
        # ends: goal id -> (its Result, the same canceled) of an ended episode, until settled
        self.node, self.running, self.results, self.ends, self.server = node, {}, {}, {}, None
        if Recognize is None:
            node.refuse.once("action", f"the recognize action is off: {MISSING} (bash "
                                       f"tools/build_interfaces.sh builds it)", warn=True)
            return
        self.wake = node.create_guard_condition(guarded(node, self.settle))
        self.server = ActionServer(node, Recognize, "recognize", self.execute, goal_callback=self.on_goal,
                                   handle_accepted_callback=self.on_accepted, cancel_callback=self.on_cancel)

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

    def on_accepted(self, handle):
        """Start the goal's episode (one running ends canceled: preempted), then execute it."""
        node, goal, key = self.node, handle.request, bytes(handle.goal_id.uuid)
        self.running[key], self.results[key] = handle, Future()
        node.apply(node.loop.start(node.now(), key, goal.object_frame, goal.object_size,
                                   goal.max_views, node.sensing, goal.time_budget))
        handle.execute()

    def on_cancel(self, handle):
        """Accept a cancel until the goal's result is sent; its episode, if it runs, ends now."""
        key, loop = bytes(handle.goal_id.uuid), self.node.loop
        if key not in self.running:
            return CancelResponse.REJECT
        if loop is not None and loop.goal == key:
            self.node.apply(loop.cancel(self.node.now()))
        self.wake.trigger()  # settled after rclpy has marked it canceling
        return CancelResponse.ACCEPT

    async def execute(self, handle):
        key = bytes(handle.goal_id.uuid)
        result = await self.results[key]
        del self.results[key]
        return result

    def feedback(self, step):
        if step.goal in self.running:
            self.running[step.goal].publish_feedback(Recognize.Feedback(
                views=step.obs.views, classification=ma.classification(
                    step.obs.probs, self.node.core.classes, step.header),
                next_view=self.node.tf.view(step.next_view), travel=step.travel, elapsed=step.elapsed))

    def ended(self, end):
        if end.goal in self.running:  # the result made now: a cleanup may free the outputs before it is sent
            canceled = replace(end, obs=replace(end.obs, status="canceled"))
            self.ends[end.goal] = self.result(end), self.result(canceled)
            self.wake.trigger()

    def settle(self):
        """Send the result of each goal whose episode ended: canceled where a cancel was
        accepted (it wins over any end not sent yet), else as its status says."""
        for key in [key for key in self.running if key in self.ends]:
            handle, (result, canceled) = self.running.pop(key), self.ends.pop(key)
            if handle.is_cancel_requested:
                result = canceled
                handle.canceled()
            elif result.status in SUCCEEDS:
                handle.succeed()
            else:  # canceled too where another start replaced it (preempted)
                handle.abort()
            self.results[key].set_result(result)

    def result(self, end):
        return Recognize.Result(status=end.obs.status, classification=self.node.outputs.verdict(end),
                                views=end.result["views"], travel=end.result["travel"],
                                elapsed=end.result["elapsed"], robot_seconds=end.result["robot_seconds"])
