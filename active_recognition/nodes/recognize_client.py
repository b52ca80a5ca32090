# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""`active-recognition recognize`: one goal to a running recognizer's `recognize` action, for
people (no `ros2` CLI needed). Prints each feedback as it comes (views, best class, probability,
next view) and the result; Ctrl-C cancels the goal and prints the result it ends with."""
import sys
import time

import rclpy
from action_msgs.msg import GoalStatus
from rclpy.action import ActionClient
from rclpy.exceptions import InvalidTopicNameException
from rclpy.executors import SingleThreadedExecutor
from rclpy.node import Node
from rclpy.signals import SignalHandlerOptions
from rclpy.validate_topic_name import validate_topic_name

from active_recognition.argument_checks import InputError
from active_recognition.nodes.demo import spin_until
from active_recognition.options.recognizer_params import check_goal
from msg_adapters import UNLABELED

SERVER_GONE_S = 3.0  # the action server gone this long: no result will come
STATES = {GoalStatus.STATUS_SUCCEEDED: "succeeded", GoalStatus.STATUS_ABORTED: "aborted",
          GoalStatus.STATUS_CANCELED: "canceled"}


def best(hypotheses):
    """(class, score) of the most probable of vision_msgs hypotheses; ('', 0) of none."""
    top = max(hypotheses, key=lambda h: h.score, default=None)
    return (top.class_id, top.score) if top is not None else ("", 0.0)


def feedback_line(fb):
    name, score = best(fb.classification.results)
    p = fb.next_view.pose.position
    where = f"next view at ({p.x:.2f}, {p.y:.2f}, {p.z:.2f}) m" if fb.next_view.header.frame_id \
        else "no next view"
    return (f"view {fb.views}: {name} p={score:.2f}, {where}, travel {fb.travel:.2f} rad, "
            f"{fb.elapsed:.1f} s")


def result_line(result, state):
    results = result.classification.results
    if results and results[0].class_id == UNLABELED:  # not recognised: the best guess follows
        name, score = best(results[1:])
        answer = f"{UNLABELED} (best guess {name} p={score:.2f})" if name else UNLABELED
    else:
        answer = "{} p={:.2f}".format(*best(results))
    return (f"result: {result.status} ({STATES.get(state, state)}): {answer}, "
            f"{result.views} views, travel {result.travel:.2f} rad, {result.elapsed:.1f} s, "
            f"{result.robot_seconds:.1f} robot s")


def interface():
    try:
        from active_recognition_interfaces.action import Recognize
    except ImportError as e:
        raise InputError(f"the Recognize action cannot be imported ({e}): bash "
                         f"tools/build_interfaces.sh builds it here, rosdep on a ROS install")
    return Recognize


def send(executor, client, goal, timeout, out=print):
    """Send `goal` (a Recognize.Goal), print its feedback, wait for its result; Ctrl-C cancels
    it -> (its Result, its GoalStatus), (None, None) when it was rejected or the server went away."""
    if not client.wait_for_server(timeout_sec=timeout):
        raise InputError(f"no recognize action server within {timeout:g} s (is the recognizer "
                         f"running and active, and the action's name right?)")
    handle = result = None
    try:
        sent = client.send_goal_async(goal, feedback_callback=lambda m: out(feedback_line(m.feedback)))
        spin_until(executor, sent.done, timeout)
        handle = sent.result() if sent.done() else None
        if handle is None or not handle.accepted:
            out("goal rejected (the recognizer logs why: another goal running, the node not active, "
                "a field out of range)")
            return None, None
        result, gone = handle.get_result_async(), None
        while not result.done():
            executor.spin_once(timeout_sec=0.1)
            gone = None if client.server_is_ready() else gone or time.monotonic()
            if gone is not None and time.monotonic() - gone > SERVER_GONE_S:
                out(f"the recognize action server went away (none for {SERVER_GONE_S:g} s): no result")
                return None, None
    except KeyboardInterrupt:
        if handle is None or not handle.accepted:
            raise
        out("canceling ...")
        handle.cancel_goal_async()
        spin_until(executor, result.done, 10.0)
    if not result.done():
        return None, None
    out(result_line(result.result().result, result.result().status))
    return result.result().result, result.result().status


def run_goal(action="/recognize", object_frame="", object_size=0.0, max_views=0, timeout=10.0,
             out=print, time_budget=0.0):
    """One goal, as `active-recognition recognize` sends it -> (its Result, its GoalStatus), or
    (None, None)."""
    recognize = interface()
    # Ctrl-C is ours (a KeyboardInterrupt that cancels the goal), not rclpy's shutdown
    rclpy.init(args=sys.argv[:1], signal_handler_options=SignalHandlerOptions.NO)
    node = Node("recognize_client")
    executor = SingleThreadedExecutor()
    executor.add_node(node)
    try:
        check_goal(object_size, max_views, time_budget)
        goal = recognize.Goal(object_frame=object_frame, object_size=float(object_size),
                              max_views=int(max_views), time_budget=float(time_budget))
        try:
            validate_topic_name(action)
        except InvalidTopicNameException as e:
            raise InputError(f"--action {action!r} is not a valid action name ({str(e).splitlines()[0]})") from e
        return send(executor, ActionClient(node, recognize, action), goal, timeout, out)
    finally:
        node.destroy_node()
        rclpy.try_shutdown()
