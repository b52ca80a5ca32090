# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""The recognizer's loop (controller.Controller) without rclpy, on a simulated clock: the shipped
procedural model and the simulated camera's core answer its requests, and each test asserts the
commands it issues and the status its episode ends with."""
from dataclasses import replace

import numpy as np
import pytest
from conftest import sure_or_not

from active_recognition.model.checkpoint import shipped
from active_recognition.model.episode import EpisodeConfig
from active_recognition.runtime.active_recognizer import ActiveRecognizer, SensingConfig
from active_recognition.runtime.controller import AskView, Controller, End, FIRST_POSE_TRIES, Refuse, Step, Timing
from active_recognition.sensing import geometry
from active_recognition.simulation.depth_sensor import SimulatedCamera


@pytest.fixture(scope="module")
def core():
    return ActiveRecognizer(str(shipped("procedural")))


@pytest.fixture
def loop(core):
    core.rng, core.sensing, core.stop = np.random.default_rng(0), SensingConfig(), EpisodeConfig()  # as built
    return Controller(core, Timing(view_timeout=3.0, max_retries=1, pose_tolerance=0.05,
                                   pose_wait=0.05, episode_timeout=60.0))


@pytest.fixture(scope="module")
def camera():
    sim = SimulatedCamera(seed=0)
    sim.load(dataset="procedural", split="test", index=3)
    return sim


def kinds(commands):
    return [type(c).__name__ for c in commands]


def answer(loop, camera, ask, now, pose=True):
    """The camera's image of request `ask`, stamped like it, with its pose first (as a camera
    publishes them) unless `pose` is False -> the loop's commands."""
    metres, position, rotation = camera.capture(ask.position, ask.rotation)
    out = loop.pose(now, ask.frame, ask.stamp, position, rotation) if pose else []
    return out + loop.image(now, ask.stamp, metres, header=("image", ask.stamp))


def run(loop, camera, commands, now, step=0.5, limit=20):
    """Answer every request until the episode ends -> (all commands, the time)."""
    seen = list(commands)
    for _ in range(limit):
        ask = [c for c in commands if isinstance(c, AskView)]
        if any(isinstance(c, End) for c in commands) or not ask:
            break
        now += step
        commands = answer(loop, camera, ask[-1], now)
        seen += commands
    return seen, now


def test_a_normal_episode_asks_steps_and_ends_with_its_answer(loop, camera):
    first = loop.start(0.0)
    assert kinds(first) == ["AskView"] and loop.state == "waiting"
    commands, now = run(loop, camera, first, 0.0)
    steps = [c for c in commands if isinstance(c, Step)]
    end = commands[-1]
    assert isinstance(end, End) and end.result["status"] == sure_or_not(end.result, loop.core.confidence)
    assert all(isinstance(c, (AskView, Step, End)) for c in commands)  # nothing refused
    # each image: a step (and the next request before it, unless it was the last)
    assert [s.obs.views for s in steps] == list(range(1, len(steps) + 1))
    assert steps[-1].next_view is None and all(s.next_view is not None for s in steps[:-1])
    views = loop.core.views_taken()
    assert end.result["travel"] == pytest.approx(geometry.travel(views))
    assert end.result["elapsed"] == pytest.approx(now) and end.result["views"] == len(steps)
    assert end.header == ("image", steps[-1].header[1]) and loop.state == "ended"
    assert loop.image(now + 1, now + 1, np.zeros((64, 64))) == [] and loop.counts["idle"] == 1


def test_travel_is_the_sum_of_great_circle_angles():
    views = [(np.pi / 2, 0.0), (np.pi / 2, np.pi / 2), (0.0, 0.0), (0.0, 1.0)]
    assert geometry.travel(views) == pytest.approx(np.pi)  # a quarter turn, a quarter, none
    rng = np.random.default_rng(5)
    a, b = rng.normal(size=3), rng.normal(size=3)
    angle = np.arccos(a @ b / np.linalg.norm(a) / np.linalg.norm(b))
    ta, pa = geometry.view_from_position(a)[1:]
    tb, pb = geometry.view_from_position(b)[1:]
    assert geometry.travel([(ta, pa), (tb, pb)]) == pytest.approx(angle)
    assert geometry.travel(np.zeros((1, 2))) == 0.0


def test_a_view_that_never_comes_is_asked_again_then_given_up_then_no_image(loop):
    asked = loop.start(0.0)[0]
    assert loop.tick(2.9) == []
    again = loop.tick(3.1)
    assert kinds(again) == ["Refuse", "AskView"] and again[0].key == "view_timeout"
    assert again[1].again and np.allclose(again[1].position, asked.position)
    moved = loop.tick(6.2)  # the resend unanswered too: the view is given up for another
    assert kinds(moved) == ["Refuse", "AskView"] and moved[0].key == "unreachable"
    assert not moved[1].again and not np.allclose(moved[1].position, asked.position)
    assert kinds(loop.tick(9.3)) == ["Refuse", "AskView"]
    ended = loop.tick(12.4)  # two views unreachable in a row (max_unreachable_views)
    assert kinds(ended) == ["Refuse", "End"] and ended[0].key == "no_image"
    assert ended[1].result["status"] == "no_image" and ended[1].result["views"] == 0
    assert loop.counts["resent"] == 2 and loop.counts["unreachable"] == 2


def test_a_late_pose_is_waited_for_and_used(loop, camera):
    ask = loop.start(0.0, sensing=SensingConfig(recentre=0.0))[0]  # about the frame's centre
    metres, position, rotation = camera.capture(*geometry_turned(ask))
    assert loop.image(0.2, ask.stamp, metres, header="h") == [] and loop.state == "classifying"
    assert loop.tick(0.22) == []  # within pose_wait of its arrival: still waiting
    out = loop.pose(0.23, "object", ask.stamp, position, rotation)
    assert kinds(out) == ["AskView", "Step"]
    taken = loop.core.views_taken()[0]
    np.testing.assert_allclose(taken, geometry.view_from_position(position)[1:], atol=1e-5)
    assert abs(taken[1] - geometry.view_from_position(ask.position)[2]) > 0.3  # not the asked one


def geometry_turned(ask, degrees=25.0):
    """The request turned about z: where an arm that overshot went."""
    c, s = np.cos(np.radians(degrees)), np.sin(np.radians(degrees))
    rz = np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]])
    return rz @ ask.position, rz @ ask.rotation


def test_a_pose_that_never_comes_is_given_up_after_the_tolerance(loop, camera):
    assert loop.pose(0.0, "object", -1.0, np.array([0.0, 0.0, 3.0]), np.eye(3)) == []  # poses come
    ask = loop.start(0.0)[0]
    metres, _, _ = camera.capture(ask.position, ask.rotation)
    assert loop.image(0.1, ask.stamp, metres) == []
    out = loop.tick(0.16)
    assert kinds(out) == ["Refuse", "AskView", "Step"] and out[0].key == "pose_wait"
    assert loop.counts["classified"] == 1 and loop.counts["matched"] == 0


def test_with_poses_required_an_image_without_one_is_refused_and_asked_again(loop, camera):
    loop = Controller(loop.core, loop.timing, pose_source="tf")
    loop.transform_missing("transform object <- camera")  # as TfPoses.poll says it
    ask = loop.start(0.0)[0]
    metres, position, rotation = camera.capture(ask.position, ask.rotation)
    assert loop.image(0.1, ask.stamp, metres) == [] and loop.tick(0.14) == []
    out = loop.tick(0.16)  # past pose_wait: refused by name, no step
    assert kinds(out) == ["Refuse"] and out[0].key == "depth/image"
    assert "no transform object <- camera for its stamp within pose_wait" in out[0].reason
    assert loop.state == "waiting" and loop.core.episode.steps == 0
    again = loop.tick(3.1)  # the view asked again after view_timeout
    assert kinds(again) == ["Refuse", "AskView"] and again[1].again
    assert loop.image(3.2, again[1].stamp, metres) == []
    out = loop.pose(3.3, "object", again[1].stamp, position, rotation)  # its transform, late
    assert kinds(out) == ["AskView", "Step"] and loop.counts["matched"] == 1


def test_a_pause_stops_the_clock_and_a_resume_asks_the_view_again(loop, camera):
    ask = loop.start(0.0)[0]
    assert loop.pause(1.0) == [] and loop.state == "paused"
    assert loop.tick(500.0) == []  # neither view_timeout nor episode_timeout while paused
    assert loop.image(500.0, 500.0, np.zeros((64, 64))) == []
    again = loop.resume(501.0)
    assert kinds(again) == ["AskView"] and np.allclose(again[0].position, ask.position)
    assert loop.state == "waiting" and loop.elapsed(502.0) == pytest.approx(2.0)
    commands, now = run(loop, camera, again, 502.0)
    assert commands[-1].result["status"] == sure_or_not(commands[-1].result, loop.core.confidence)
    assert commands[-1].result["elapsed"] == pytest.approx(now - 500.0)


def test_an_episode_past_episode_timeout_ends_timeout_with_its_best_guess(loop, camera):
    loop.timing = Timing(view_timeout=100.0, episode_timeout=10.0)
    ask = loop.start(0.0)[0]
    first = answer(loop, camera, ask, 1.0)
    assert kinds(first) == ["AskView", "Step"]
    assert loop.tick(9.9) == []
    out = loop.tick(10.1)
    assert kinds(out) == ["Refuse", "End"] and out[0].key == "episode_timeout"
    assert out[1].result["status"] == "timeout" and out[1].result["label"] == first[1].obs.label


def test_a_cancel_ends_at_once_with_the_best_guess_and_no_request_follows(loop, camera):
    ask = loop.start(0.0, goal="g")[0]
    first = answer(loop, camera, ask, 0.5)
    out = loop.cancel(0.6)
    assert kinds(out) == ["End"] and out[0].goal == "g" and not out[0].replaced
    assert out[0].result["status"] == "canceled" and out[0].result["label"] == first[1].obs.label
    assert out[0].result["views"] == 1
    assert loop.tick(100.0) == [] and loop.cancel(100.0) == []  # nothing after it
    metres, _, _ = camera.capture(first[0].position, first[0].rotation)
    assert loop.image(101.0, 101.0, metres) == [] and loop.counts["idle"] == 1


def test_a_second_start_ends_the_first_canceled_and_runs_on(loop, camera):
    first = loop.start(0.0, goal="a", max_views=2)
    answer(loop, camera, first[0], 0.5)
    second = loop.start(1.0, goal="b", object_size=2.0)
    assert kinds(second) == ["End", "AskView"]
    assert second[0].goal == "a" and second[0].result["status"] == "canceled" and second[0].replaced
    assert loop.core.sensing.object_size == 2.0 and loop.core.episode.config.max_views == 10
    commands, _ = run(loop, camera, second[1:], 1.0)
    assert commands[-1].goal == "b" and commands[-1].result["status"] != "canceled"


def test_max_views_of_a_start_stops_the_episode_there(loop, camera):
    commands, _ = run(loop, camera, loop.start(0.0, max_views=1), 0.0)
    assert kinds(commands) == ["AskView", "Step", "End"] and commands[-1].result["views"] == 1


def test_inputs_are_refused_by_name(loop, camera):
    ask = loop.start(100.0)[0]
    out = loop.pose(100.0, "world", ask.stamp, ask.position, ask.rotation)
    assert kinds(out) == ["Refuse"] and out[0].key == "camera/pose" and "'world'" in out[0].reason
    assert loop.image(100.0, 99.0, np.zeros((4, 4))) == [] and loop.counts["stale"] == 1
    out = loop.image(100.0, 0.0, np.zeros((4, 4)))  # another clock
    assert kinds(out) == ["Refuse"] and "clock" in out[0].reason
    assert loop.info(100.0, refused="K all zero") == [Refuse("depth/camera_info",
                                                             "camera_info refused: K all zero")]
    out = loop.image(100.0, ask.stamp, np.zeros((4, 4)))
    assert "camera_info was refused" in out[0].reason and loop.counts["rejected"] == 2


def test_a_bug_in_the_core_is_not_called_a_refused_image(loop, monkeypatch):
    ask = loop.start(0.0)[0]

    def broken(*args):
        raise ValueError("a bug")
    monkeypatch.setattr(loop.core, "observe", broken)
    assert loop.image(0.1, ask.stamp, np.zeros((64, 64))) == []  # waits for its pose
    with pytest.raises(ValueError, match="a bug"):
        loop.tick(0.2)


def test_the_waits_for_poses_are_recorded_for_every_image(loop, camera):
    ask = loop.start(0.0)[0]
    metres, position, rotation = camera.capture(ask.position, ask.rotation)
    assert loop.image(0.1, ask.stamp, metres) == []
    assert "Step" in kinds(loop.pose(0.13, "object", ask.stamp, position, rotation))
    assert list(loop.waited) == [pytest.approx(0.03)]  # its pose came 30 ms after it
    ask = loop.start(1.0)[-1]  # after the End of the first episode, where it was still going on
    metres, position, rotation = camera.capture(ask.position, ask.rotation)
    out = loop.pose(1.0, "object", ask.stamp, position, rotation) + loop.image(1.1, ask.stamp, metres)
    assert "Step" in kinds(out) and loop.waited[-1] == 0.0  # its pose came first
    report = loop.report(1.2)[2]
    assert report["pose wait p99 (ms)"] == pytest.approx(np.percentile([30.0, 0.0], 99))
    assert report["images matched to a measured pose (%)"] == 100.0


def late_pose_loop(loop, camera, pose_reask=0.15):
    """A loop that waits pose_wait 3.5 s and asks again after pose_reask; its first view answered
    with its pose (poses come) at 0.5 s -> the request for the second view."""
    loop.timing = Timing(view_timeout=3.0, pose_tolerance=0.05, pose_wait=3.5,
                         pose_reask=pose_reask)
    loop.core.stop = replace(loop.core.stop, entropy_threshold=0.0)  # configured never sure: the episode goes on
    first = loop.start(0.0, max_views=10, sensing=SensingConfig(recentre=0.0))[0]
    out = answer(loop, camera, first, 0.5)
    assert kinds(out) == ["AskView", "Step"]
    return out[0]


def test_a_late_pose_has_its_view_asked_again_and_the_next_pose_is_used(loop, camera):
    ask = late_pose_loop(loop, camera)
    metres, position, rotation = camera.capture(*geometry_turned(ask))
    assert loop.image(1.0, ask.stamp, metres) == [] and loop.state == "classifying"  # pose lost
    assert loop.tick(1.14) == []
    again = loop.tick(1.16)  # pose_reask after the image: the same view again
    assert kinds(again) == ["AskView"] and again[0].again
    assert np.allclose(again[0].position, ask.position)
    assert loop.tick(1.4) == [] and loop.counts["reasked"] == 1  # its answer on its way: no other
    metres, position, rotation = camera.capture(*geometry_turned(again[0]))
    assert loop.image(1.5, again[0].stamp, metres) == [] and loop.tick(1.64) == []
    third = loop.tick(1.66)  # the answer's pose late too: asked again once more
    assert kinds(third) == ["AskView"] and third[0].again and loop.counts["reasked"] == 2
    out = loop.pose(1.8, "object", third[0].stamp, position, rotation) + \
        loop.image(1.8, third[0].stamp, metres, header="h3")
    assert kinds(out) == ["AskView", "Step"] and out[1].header == "h3"
    assert loop.counts["matched"] == 2
    taken = loop.core.views_taken()[-1]  # the measured pose, not the view asked for
    np.testing.assert_allclose(taken, geometry.view_from_position(position)[1:], atol=1e-5)
    # the view's split: its image 0.5 s after the request, its pose 0.8 s after the image
    view = loop.view_waits.episode[-1]
    assert (view["stamp"], view["image"], view["pose"]) == (third[0].stamp, pytest.approx(0.5),
                                                            pytest.approx(0.8))
    report = loop.report(1.9)[2]
    assert report["view pose wait p50 (ms)"] == pytest.approx(400.0)  # views 0 and 800 ms
    assert report["view image wait p99 (ms)"] == pytest.approx(np.percentile([500.0, 500.0], 99))
    assert report["views asked again for a late pose"] == 2
    end = loop.cancel(2.0)[0]
    assert [v["pose"] for v in end.result["view_waits"]] == [0.0, pytest.approx(0.8)]


def test_a_pose_late_past_its_views_asking_again_still_finds_its_image(loop, camera):
    ask = late_pose_loop(loop, camera)
    metres, position, rotation = camera.capture(*geometry_turned(ask))
    assert loop.image(1.0, ask.stamp, metres, header="h1") == []
    again = loop.tick(1.16)
    assert kinds(again) == ["AskView"]
    assert loop.image(1.3, again[0].stamp, np.zeros_like(metres), header="h2") == []  # its answer
    out = loop.pose(1.35, "object", ask.stamp, position, rotation)  # the first image's pose, late
    assert kinds(out) == ["AskView", "Step"] and out[1].header == "h1"
    assert loop.view_waits.episode[-1]["pose"] == pytest.approx(0.35)


def test_no_view_is_asked_again_with_pose_reask_zero_nor_before_a_first_pose(loop, camera):
    ask = late_pose_loop(loop, camera, pose_reask=0.0)
    metres, _, _ = camera.capture(ask.position, ask.rotation)
    assert loop.image(1.0, ask.stamp, metres) == []
    assert [loop.tick(t) for t in (1.2, 2.0, 4.4)] == [[], [], []]  # until pose_wait
    assert "Step" in kinds(loop.tick(4.6)) and loop.counts["reasked"] == 0
    tf = Controller(loop.core, Timing(pose_wait=3.5, pose_reask=0.15), pose_source="tf")  # TF: waited for
    ask = tf.start(5.0)[-1]
    assert tf.image(5.1, ask.stamp, metres) == [] and tf.tick(5.5) == [] and tf.counts["reasked"] == 0
    loop.poses.clear()  # a camera that publishes no pose
    loop.timing = Timing(pose_wait=3.5, pose_reask=0.15)
    ask = loop.start(10.0)[-1]
    assert loop.image(10.1, ask.stamp, metres) == [] and loop.tick(10.5) == []
    assert loop.counts["reasked"] == 0


def test_before_a_first_pose_a_view_is_asked_again_only_when_camera_pose_has_a_publisher(loop, camera):
    """A driver's very first pose lost beside its frame: with a publisher of camera/pose there,
    the view is asked again after pose_reask instead of waiting pose_wait (3.5 s)."""
    loop.timing = Timing(pose_wait=3.5, pose_reask=0.15)
    ask = loop.start(0.0)[-1]
    metres, position, rotation = camera.capture(*geometry_turned(ask))
    assert not loop.poses and loop.image(0.2, ask.stamp, metres) == []  # its pose lost
    assert loop.tick(0.4) == []  # nobody publishes camera/pose (yet): no re-ask
    again = loop.tick(0.4, pose_publishers=True)
    assert kinds(again) == ["AskView"] and again[0].again and loop.counts["reasked"] == 1
    out = loop.pose(0.6, "object", again[0].stamp, position, rotation) + \
        loop.image(0.6, again[0].stamp, metres)
    assert "Step" in kinds(out) and loop.counts["matched"] == 1
    assert loop.view_waits.episode[-1]["pose"] == pytest.approx(0.4)  # from the first image


def test_before_a_first_pose_a_publisher_that_never_sends_costs_a_bounded_number_of_tries(loop, camera):
    loop.timing = Timing(pose_wait=3.5, pose_reask=0.15)
    ask = loop.start(0.0)[-1]
    metres, _, _ = camera.capture(*geometry_turned(ask))
    now, asks = 0.2, 0
    while now < 3.0:  # each try answered by an image 0.1 s after it, never a pose
        out = loop.image(now, loop.asked_at, metres) + loop.tick(now + 0.2, pose_publishers=True)
        asks += kinds(out).count("AskView")
        now += 0.3
    assert asks == loop.counts["reasked"] == FIRST_POSE_TRIES - 1
    assert "Step" in kinds(loop.tick(3.8, pose_publishers=True))  # pose_wait from the first image
