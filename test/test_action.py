# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""The `recognize` action in one process: the recognizer, the simulated camera and an action
client over real topics. Feedback per image and a result; a cancel; a goal while one runs;
the goal's fields; refused goals. Across processes: test_cross_process_action.py."""
import sys
import time

import numpy as np
import pytest
from action_msgs.msg import GoalStatus

from conftest import import_ros, need_vision_msgs

rclpy = import_ros("rclpy")
need_vision_msgs()
from geometry_msgs.msg import PoseStamped  # noqa: E402
from rclpy.action import ActionClient  # noqa: E402
from rclpy.parameter import Parameter  # noqa: E402

import msg_adapters as ma  # noqa: E402
from active_recognition.model.checkpoint import shipped  # noqa: E402
from active_recognition.nodes.demo import ros_session, spin_until  # noqa: E402
from active_recognition.nodes.recognize_client import feedback_line, result_line  # noqa: E402
from active_recognition.nodes.recognize_server import RecognizeServer  # noqa: E402
from active_recognition.nodes.recognizer import Recognizer  # noqa: E402
from active_recognition.nodes.simulated_camera import SimulatedCameraNode  # noqa: E402
from active_recognition.sensing import geometry  # noqa: E402

Recognize = pytest.importorskip("active_recognition_interfaces.action").Recognize \
    if not __import__("os").environ.get("CI") else \
    __import__("active_recognition_interfaces.action", fromlist=["Recognize"]).Recognize


class Goal:
    """One goal sent: its feedback, its result, and the times they came."""

    def __init__(self, executor, client, **fields):
        self.feedback, self.times = [], []
        self.executor = executor
        self.sent = client.send_goal_async(Recognize.Goal(**fields), feedback_callback=self.on_feedback)
        assert spin_until(executor, self.sent.done, 10)
        self.handle = self.sent.result()
        self.result = self.handle.get_result_async() if self.handle.accepted else None

    def on_feedback(self, msg):
        self.feedback.append(msg.feedback)
        self.times.append(time.monotonic())

    def wait(self, timeout=30):
        assert spin_until(self.executor, self.result.done, timeout), "no result"
        return self.result.result().result, self.result.result().status


@pytest.fixture
def loop():
    def make(**params):
        ctx, executor = session.__enter__()
        made.append(session)
        recognizer = Recognizer(context=ctx, parameter_overrides=[
            Parameter(k, value=v) for k, v in {"checkpoint": str(shipped("procedural")), "seed": 1,
                                               **params}.items()])
        camera = SimulatedCameraNode(context=ctx, parameter_overrides=[Parameter("index", value=4)])
        client_node = rclpy.create_node("action_client", context=ctx)
        views = []
        client_node.create_subscription(PoseStamped, "next_view",
                                        lambda m: views.append((time.monotonic(), m)), 100)
        for n in (recognizer, camera, client_node):
            executor.add_node(n)
        client = ActionClient(client_node, Recognize, "recognize")
        assert client.wait_for_server(timeout_sec=10)
        return executor, recognizer, camera, client, views

    session, made = ros_session(), []
    yield make
    for s in made:
        s.__exit__(None, None, None)


def answered(result, status, confidence):
    """(best class, sure) of a goal that ended with an answer, asserting that it succeeded as
    recognized where its best guess reaches the node's confidence, else aborted as unsure with
    UNLABELED first and the best guess after it."""
    hypotheses = result.classification.results
    unlabeled = hypotheses[0].class_id == ma.UNLABELED
    best = max(hypotheses[1:] if unlabeled else hypotheses, key=lambda h: h.score)
    sure = best.score >= confidence
    assert (status, result.status, unlabeled) == (
        (GoalStatus.STATUS_SUCCEEDED, "recognized", False) if sure else (GoalStatus.STATUS_ABORTED, "unsure", True))
    return best.class_id, sure


def test_a_goal_gets_feedback_for_each_image_and_a_result(loop):
    executor, recognizer, camera, client, views = loop()
    goal = Goal(executor, client)
    result, status = goal.wait()
    best, sure = answered(result, status, recognizer.core.confidence)
    assert best == "bathtub"  # procedural/test[4]
    assert [f.views for f in goal.feedback] == list(range(1, result.views + 1))
    taken = recognizer.core.views_taken()
    assert result.travel == pytest.approx(geometry.travel(taken), rel=1e-5) and result.travel > 0
    assert goal.feedback[-1].travel == pytest.approx(result.travel, rel=1e-5)
    assert 0 < goal.feedback[-1].elapsed <= result.elapsed < 30
    # each feedback's next_view is the request that followed its image; none after the last
    asked = [m for _, m in views]
    assert [f.next_view.pose for f in goal.feedback[:-1]] == [m.pose for m in asked[1:len(goal.feedback)]]
    assert goal.feedback[-1].next_view.header.frame_id == ""
    assert "view 1:" in feedback_line(goal.feedback[0]) and (
        "recognized (succeeded)" if sure else "unsure (aborted)") in result_line(result, status)


def test_a_cancel_after_the_second_image_ends_canceled_at_once_and_no_view_follows(loop):
    executor, recognizer, camera, client, views = loop(entropy_threshold=0.0)  # never sure
    goal = Goal(executor, client)
    assert spin_until(executor, lambda: len(goal.feedback) >= 2, 20)
    canceled = goal.handle.cancel_goal_async()
    result, status = goal.wait()
    assert spin_until(executor, canceled.done, 10) and len(canceled.result().goals_canceling) == 1
    assert status == GoalStatus.STATUS_CANCELED and result.status == "canceled"
    # at once: no image after the cancel was classified, and nothing is left to ask a view again
    assert result.views == len(goal.feedback) >= 2
    assert result.classification.results[0].class_id == "UNLABELED"  # best guess after it
    assert recognizer.loop.state == "ended" and recognizer.loop.asked_at is None
    stamps = [ma.stamp_seconds(m.header.stamp) for _, m in views]
    assert max(stamps) <= stamps[0] + result.elapsed + 1e-6  # none after the episode's end


class HeldCamera:
    """The simulated camera with its answers held: each next_view it gets waits in `asked` until
    the test calls release(), which renders and publishes the latest (poses too unless
    `poses` is a list, where they wait instead)."""

    def __init__(self, monkeypatch, poses=None):
        self.asked, self.poses, self.answer = [], poses, SimulatedCameraNode.on_pose
        monkeypatch.setattr(SimulatedCameraNode, "on_pose", lambda node, msg: self.asked.append((node, msg)))

    def release(self):
        node, msg = self.asked[-1]
        self.asked.clear()
        if self.poses is not None:
            node.pub_pose = type("Held", (), {"publish": lambda _, pose: self.poses.append(pose)})()
        self.answer(node, msg)


def cancel_hook(monkeypatch, before=lambda: None, after=lambda server, key: None):
    """Run `before` and `after` around the recognizer's cancel callback (in its callback group)."""
    cancel = RecognizeServer.on_cancel

    def on_cancel(server, handle):
        before()
        response = cancel(server, handle)
        after(server, bytes(handle.goal_id.uuid))
        return response
    monkeypatch.setattr(RecognizeServer, "on_cancel", on_cancel)


def ends_canceled(goal, views):
    result, status = goal.wait()
    assert (status, result.status, result.views) == (GoalStatus.STATUS_CANCELED, "canceled", views)
    assert result.classification.results[0].class_id == "UNLABELED"


NO_RESEND = {"entropy_threshold": 0.0, "view_timeout": 3600.0}  # never sure; a held view waits


def test_a_cancel_while_an_image_is_in_the_network_ends_canceled(loop, monkeypatch):
    camera = HeldCamera(monkeypatch)
    cancel_hook(monkeypatch, before=camera.release)  # the camera answers now: its image is on its way
    executor, recognizer, _, client, views = loop(**NO_RESEND)
    goal = Goal(executor, client)
    assert spin_until(executor, lambda: camera.asked, 20)
    camera.release()
    assert spin_until(executor, lambda: goal.feedback and camera.asked, 20)  # view 2 asked, not answered
    idle = recognizer.loop.counts["idle"]
    goal.handle.cancel_goal_async()
    ends_canceled(goal, 1)
    assert spin_until(executor, lambda: recognizer.loop.counts["idle"] > idle, 10)  # it came after: unused


def test_a_cancel_while_the_controller_holds_an_image_ends_canceled(loop, monkeypatch):
    camera, undecided = HeldCamera(monkeypatch), []
    # rclpy marks the goal canceling after this callback returns: no result may be decided before
    cancel_hook(monkeypatch, after=lambda server, key: undecided.append(not server.results[key].done()))
    executor, recognizer, _, client, views = loop(**NO_RESEND, pose_wait=60.0)
    goal = Goal(executor, client)
    assert spin_until(executor, lambda: camera.asked, 20)
    camera.release()
    assert spin_until(executor, lambda: goal.feedback and camera.asked, 20)
    camera.poses = []  # view 2's image comes, its pose waits: the controller keeps the image
    camera.release()
    assert spin_until(executor, lambda: recognizer.loop.state == "classifying", 20)
    goal.handle.cancel_goal_async()
    ends_canceled(goal, 1)
    assert undecided == [True] and recognizer.loop.pending is None


def test_a_cancel_after_the_episode_ended_before_its_result_was_sent_ends_canceled(loop, monkeypatch):
    cancels, settle = [], RecognizeServer.settle
    monkeypatch.setattr(RecognizeServer, "settle", lambda server: settle(server) if cancels else None)  # held
    cancel_hook(monkeypatch, before=lambda: cancels.append(1))
    executor, recognizer, camera, client, views = loop(entropy_threshold=0.0)
    goal = Goal(executor, client, max_views=2)
    assert spin_until(executor, lambda: recognizer.action.ends, 20)  # ended unsure; its result unsent
    assert not goal.result.done()
    goal.handle.cancel_goal_async()
    ends_canceled(goal, 2)


@pytest.mark.parametrize("policy", ["reject", "preempt"])
def test_a_second_goal_while_one_runs_is_rejected_or_preempts(loop, policy):
    executor, recognizer, camera, client, views = loop(goal_policy=policy, entropy_threshold=0.0)
    first = Goal(executor, client)
    assert spin_until(executor, lambda: len(first.feedback) >= 1, 20)
    second = Goal(executor, client, max_views=2)
    if policy == "reject":
        assert not second.handle.accepted and "another goal is running" in \
            recognizer.refuse.latest["recognize"]
        result, status = first.wait()
        # never sure (entropy_threshold 0: confidence 1): 10 views end unsure, the goal aborted
        assert status == GoalStatus.STATUS_ABORTED and (result.status == "timeout" or
                                                        (result.status == "unsure" and result.views == 10))
        return
    result, status = first.wait()  # at once on a quiet machine; a busy one's executor may take seconds
    assert status == GoalStatus.STATUS_ABORTED and result.status == "canceled", (status, result)
    result, status = second.wait()
    # rclpy's client drops feedback that comes before it has read the goal's acceptance (a busy
    # machine's race), so the first may be missing; what comes is in order and ends at the result
    seen = [f.views for f in second.feedback]
    assert result.views == 2 and seen in ([1, 2], [2]), (status, result, seen)


def test_the_goals_fields_set_the_frame_the_size_and_the_views(loop):
    executor, recognizer, camera, client, views = loop()
    assert Goal(executor, client).wait()[0].views >= 1  # the node's own settings; K known after
    assert recognizer.core.sensing.object_size == 1.0 and {m.header.frame_id for _, m in views} == {"object"}
    before = len(views)
    goal = Goal(executor, client, object_frame="table", object_size=2.0, max_views=1)
    result, status = goal.wait()
    assert result.views == 1 and result.travel == 0.0
    assert {m.header.frame_id for _, m in views[before:]} == {"table"}  # the camera answered in it too
    radius = np.linalg.norm([getattr(views[before][1].pose.position, a) for a in "xyz"])
    assert recognizer.core.sensing.object_size == 2.0  # as far as an object of 2 m needs
    assert radius == pytest.approx(recognizer.core.standoff(recognizer.loop.k), rel=1e-6)


@pytest.mark.parametrize("fields, why", [({"object_size": float("nan")}, "object_size"),
                                         ({"object_size": 1e-5}, "object_size"),
                                         ({"max_views": 1001}, "max_views")])
def test_a_bad_goal_is_rejected_by_name(loop, fields, why):
    executor, recognizer, camera, client, views = loop()
    goal = Goal(executor, client, **fields)
    assert not goal.handle.accepted and why in recognizer.refuse.latest["recognize"]
    assert views == [] and recognizer.loop.state == "idle"


def test_an_inactive_node_rejects_goals_and_reset_still_works(loop):
    executor, recognizer, camera, client, views = loop()
    recognizer.trigger_deactivate()
    goal = Goal(executor, client)
    assert not goal.handle.accepted and "inactive" in recognizer.refuse.latest["recognize"]


def test_every_attribute_of_the_node_is_made_at_its_start(loop):
    """The node's state is named in one place: configure, activate, goals, a cancel, a reset,
    deactivate and cleanup add no attribute its constructor did not make."""
    from std_srvs.srv import Trigger

    executor, recognizer, camera, client, views = loop(autostart=False)
    made = set(vars(recognizer))
    recognizer.trigger_configure()
    recognizer.trigger_activate()
    goal = Goal(executor, client, max_views=2)
    assert goal.wait()[0].views == 2
    goal = Goal(executor, client)
    goal.handle.cancel_goal_async()
    goal.wait()
    assert recognizer.on_reset(Trigger.Request(), Trigger.Response()).success
    spin_until(executor, lambda: not recognizer.loop.running, 10)
    recognizer.trigger_deactivate()
    recognizer.trigger_cleanup()
    assert set(vars(recognizer)) - made == set()


def test_a_cleanup_during_a_goal_aborts_it_with_its_result(loop):
    executor, recognizer, camera, client, views = loop(entropy_threshold=0.0)
    goal = Goal(executor, client)
    assert spin_until(executor, lambda: len(goal.feedback) >= 1, 20)
    recognizer.trigger_deactivate()
    recognizer.trigger_cleanup()
    result, status = goal.wait(5)
    assert status == GoalStatus.STATUS_ABORTED and result.status == "canceled"
    assert result.views == len(goal.feedback) and result.classification.results[0].class_id == "UNLABELED"


def test_every_rejected_goal_is_logged_with_its_reason(loop):
    executor, recognizer, camera, client, views = loop()
    logged = []
    recognizer.refuse.logger = type("Log", (), {"warn": lambda self, text: logged.append(text)})()
    for fields in ({"object_size": float("nan")}, {"max_views": 1001}, {"object_size": -1.0}):
        assert not Goal(executor, client, **fields).handle.accepted
    assert len(logged) == 3 and "got nan" in logged[0] and "1001" in logged[1] and "-1" in logged[2]


def test_the_client_says_when_the_server_goes_away(loop, monkeypatch):
    from active_recognition.nodes import recognize_client

    executor, recognizer, camera, client, views = loop()
    monkeypatch.setattr(recognize_client, "SERVER_GONE_S", 0.5)
    executor.remove_node(camera)  # no image comes: the goal runs on
    camera.destroy_node()
    timers = []

    def server_gone():
        timers[0].cancel()
        recognizer.action.destroy()
    timers.append(recognizer.create_timer(0.5, server_gone))
    lines, start = [], time.monotonic()
    assert recognize_client.send(executor, client, Recognize.Goal(), 10, out=lines.append) == (None, None)
    assert time.monotonic() - start < 5 and "went away" in lines[-1]


@pytest.mark.parametrize("args, says", [
    (["--timeout", "0.5"], "no recognize action server within 0.5 s"),
    (["--action", "bad name!"], "--action 'bad name!' is not a valid action name"),
    (["--object-size", "0.0005"], "object_size must be 0 (the node's) or 0.001 to 100 m"),
    (["--max-views", "1001"], "--max-views: must be an integer from 0 to 1000"),
    (["--time-budget", "-1"], "--time-budget: must be")])
def test_the_client_refuses_in_one_line_and_exits_2(args, says):
    from conftest import run_side_by_side

    done, = run_side_by_side([[sys.executable, "-m", "active_recognition.cli", "recognize", "--timeout", "0.5",
                               *args]])
    assert done.returncode == 2, done.stderr
    assert says in done.stderr and len(done.stderr.strip().splitlines()) == 1, done.stderr


def test_the_client_sends_its_time_budget_in_the_goal(monkeypatch):
    from active_recognition.argument_checks import InputError
    from active_recognition.nodes import recognize_client

    sent = []
    monkeypatch.setattr(recognize_client, "send", lambda executor, client, goal, timeout, out: sent.append(goal))
    recognize_client.run_goal(object_size=0.5, max_views=4, time_budget=7.5, timeout=0.1)
    assert [(g.object_size, g.max_views, g.time_budget) for g in sent] == [(0.5, 4, 7.5)]
    with pytest.raises(InputError, match="time_budget must be 0"):
        recognize_client.run_goal(time_budget=-2.0, timeout=0.1)


def test_a_goals_time_budget_ends_it_before_the_next_view_would_overrun(loop):
    executor, recognizer, camera, client, views = loop(budget_entropy_threshold=0.0)  # only the budget stops it
    goal = Goal(executor, client, time_budget=3.0)
    result, status = goal.wait()
    answered(result, status, recognizer.core.confidence)  # recognized or unsure, as the confidence says
    taken = recognizer.core.views_taken()
    assert result.robot_seconds == pytest.approx(recognizer.loop.cost.seconds(taken), rel=1e-5)
    assert result.robot_seconds <= 3.0 < result.robot_seconds + recognizer.loop.cost.next_view(
        taken, recognizer.core.view)
    assert 1 <= result.views < 10 and goal.feedback[-1].next_view.header.frame_id == ""
    assert not Goal(executor, client, time_budget=-1.0).handle.accepted
