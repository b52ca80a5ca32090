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
from rclpy.action import ActionServer, CancelResponse, GoalResponse
from rclpy.task import Future

from active_recognition.argument_checks import InputError
from active_recognition.nodes import guarded

try:
    from active_recognition_interfaces.action import Recognize
except ImportError as e:  # built by tools/build_interfaces.sh, or rosdep on a ROS install
    Recognize, MISSING = None, str(e)
SUCCEEDS = ("recognized", "unknown")  # the statuses whose goal succeeds


class RecognizeServer:
    """Every goal's state is decided in the node's callbacks (one mutually exclusive group): a
    goal is accepted and its episode started, canceled, ended and settled there, never in its
    execute coroutine, which only waits for its result. rclpy marks a goal canceling after
    on_cancel returns, so an end is settled by a callback of its own (`wake`), which runs after
    that: a cancel accepted before a goal's result is sent ends it CANCELED, whatever ended
    its episode. The node's own part comes by the constructor (admit, start, cancel)."""

    def __init__(self, node, refuse, admit, start, cancel):
        # running: goal id (bytes; the controller's goal) -> its handle, until its result is sent
        # results: goal id -> a Future of its Result (execute waits on it)
        # ends: goal id -> (its Result, the same canceled) of an ended episode, until settled
        self.running, self.results, self.ends, self.server = {}, {}, {}, None
        self.refuse, self.admit, self.start, self.cancel = refuse, admit, start, cancel
        if Recognize is None:
            refuse.once("action", f"the recognize action is off: {MISSING} (bash tools/build_interfaces.sh builds it)",
                        warn=True)
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
        try:
            self.admit(goal, busy=bool(self.running))
        except InputError as e:  # goals are few: each refusal is logged
            self.refuse.always("recognize", f"recognize goal rejected: {e}")
            return GoalResponse.REJECT
        return GoalResponse.ACCEPT

    def on_accepted(self, handle):
        """Start the goal's episode (one running ends canceled: preempted), then execute it."""
        key = bytes(handle.goal_id.uuid)
        self.running[key], self.results[key] = handle, Future()
        self.start(key, handle.request)
        handle.execute()

    def on_cancel(self, handle):
        """Accept a cancel until the goal's result is sent; its episode, if it runs, ends now."""
        key = bytes(handle.goal_id.uuid)
        if key not in self.running:
            return CancelResponse.REJECT
        self.cancel(key)  # the node ends its episode if it still runs
        self.wake.trigger()  # settled after rclpy has marked it canceling
        return CancelResponse.ACCEPT

    async def execute(self, handle):
        key = bytes(handle.goal_id.uuid)
        result = await self.results[key]
        del self.results[key]
        return result

    def serves(self, goal):
        """Whether `goal` (a controller's goal) is one of this server's, its result not sent yet."""
        return goal in self.running

    def feedback(self, goal, step, classification, next_view):
        """A classified image of `goal`'s episode (a Step), its Classification and next_view."""
        self.running[goal].publish_feedback(Recognize.Feedback(
            views=step.obs.views, classification=classification, next_view=next_view,
            travel=step.travel, elapsed=step.elapsed))

    def ended(self, goal, end, verdict, canceled):
        """The episode of `goal` is over (an End), its Classification `verdict` (`canceled` if a cancel came first)."""
        self.ends[goal] = self.result(end, end.obs.status, verdict), self.result(end, "canceled", canceled)
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

    @staticmethod
    def result(end, status, classification):
        return Recognize.Result(status=status, classification=classification,
                                views=end.result["views"], travel=end.result["travel"],
                                elapsed=end.result["elapsed"], robot_seconds=end.result["robot_seconds"])
