# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0


"""Every input of a running recognizer is checked on arrival: each bad one is refused by name,
never reaches the core, and the node goes on to recognise the next good object; no exception
escapes a callback; a request no image answers is sent again, then given up (no_image)."""
import math

import numpy as np
import pytest

from conftest import import_ros, load_benchmark, sure_or_not

rclpy = import_ros("rclpy")
from geometry_msgs.msg import PoseStamped  # noqa: E402
from rclpy.node import Node  # noqa: E402
from rclpy.parameter import Parameter  # noqa: E402
from rclpy.qos import qos_profile_sensor_data  # noqa: E402
from sensor_msgs.msg import CameraInfo, Image  # noqa: E402
from std_srvs.srv import Trigger  # noqa: E402

import msg_adapters as ma  # noqa: E402
from active_recognition.nodes.demo import DemoClient, recognize, ros_session, spin_until  # noqa: E402
from active_recognition.nodes.recognizer import PARAMS, Recognizer  # noqa: E402
from active_recognition.nodes.simulated_camera import SimulatedCameraNode  # noqa: E402
from active_recognition.sensing import geometry  # noqa: E402

# the recognizer's default is the ModelNet10 model; these loops show procedural objects
PROCEDURAL = load_benchmark("common").shipped_checkpoint()


def info(width, height, fx, fy, cx, cy, **k):
    msg = ma.camera_info(geometry.Intrinsics(640, 480, 385.0, 385.0, 319.5, 239.5))
    msg.width, msg.height = width, height
    msg.k = [fx, 0.0, cx, 0.0, fy, cy, 0.0, 0.0, 1.0]
    for i, v in k.items():
        msg.k[int(i[1:])] = v
    return msg


def pose(frame="object", position=(0.0, -1.5, 0.3), w=None):
    msg = ma.view_to_pose(1.4, -math.pi / 2, 1.5, frame)
    msg.pose.position.x, msg.pose.position.y, msg.pose.position.z = position
    if w is not None:
        msg.pose.orientation.w = w
    return msg


@pytest.fixture
def node():
    with ros_session() as (ctx, executor):
        camera = SimulatedCameraNode(context=ctx, parameter_overrides=[Parameter("index", value=0)])
        recognizer = Recognizer(context=ctx, parameter_overrides=[
            PROCEDURAL, Parameter("seed", value=7), Parameter("view_timeout", value=0.5)])
        client = DemoClient(context=ctx)
        bad = Node("bad_inputs", context=ctx)
        for n in (camera, recognizer, client, bad):
            executor.add_node(n)
        pubs = {kind: bad.create_publisher(kind, topic, qos_profile_sensor_data)
                for kind, topic in ((CameraInfo, "depth/camera_info"),
                                    (PoseStamped, "camera/pose"), (Image, "depth/image"))}
        assert spin_until(executor, client.reset.service_is_ready, 10)
        assert spin_until(executor, lambda: all(p.get_subscription_count() for p in pubs.values()),
                          10)
        yield executor, recognizer, client, pubs


def stamped(msg, recognizer, offset=0.0):
    t = recognizer.get_clock().now().nanoseconds * 1e-9 + offset
    msg.header.stamp.sec, msg.header.stamp.nanosec = int(t), int(t % 1 * 1e9)
    return msg


def test_bad_inputs_are_refused_by_name_and_the_next_object_is_answered(node):
    executor, recognizer, client, pubs = node
    recognizer.loop.start(recognizer.now())  # an episode in progress: a refused input must not touch it
    image = ma.metres_to_image(np.full((480, 640), 0.8, np.float32))
    bad = [  # (message, key of the refusal, what the warning must name)
        (info(64, 64, 60.0, 60.0, 320.0, 240.0), "depth/camera_info", "k[2] (cx)"),  # the crash
        (info(640, 480, 1e-3, 1e-3, 319.5, 239.5), "depth/camera_info", "k[0] (fx)"),  # absurd
        (info(640, 480, 385.0, 385.0, 319.5, 239.5, k8=0.0), "depth/camera_info", "k[8]"),
        (info(640, 480, 385.0, 1e5, 319.5, 239.5), "depth/camera_info", "k[4] (fy)"),
        (info(0, 480, 385.0, 385.0, 319.5, 239.5), "depth/camera_info", "camera size 0x480"),
        # the camera is unknown again: an image waits, not guessed through (it reached the model, before)
        (stamped(ma.metres_to_image(np.full((480, 640), 0.8, np.float32)), recognizer), "depth/image",
         "the latest camera_info was refused (camera_info: camera size 0x480"),
        (stamped(pose("world"), recognizer), "camera/pose", "header.frame_id 'world'"),
        (stamped(pose(position=(1e6, 0.0, 0.0)), recognizer), "camera/pose", "pose.position"),
        # a camera inside the object (its box: object_size about the centre) is refused too
        (stamped(pose(position=(0.05, 0.0, 0.02)), recognizer), "camera/pose",
         "inside the object's box (edge 1 m, the parameter object_size"),
        (stamped(pose(w=2.0), recognizer), "camera/pose", "unit quaternion"),
        (stamped(pose(), recognizer, offset=-3600.0), "camera/pose", "header.stamp"),
        (stamped(image, recognizer, offset=-3600.0), "depth/image", "header.stamp"),
        (image, "depth/image", "header.stamp"),  # never stamped
        (stamped(ma.metres_to_image(np.full((48, 64), 0.8, np.float32)), recognizer),
         "depth/image", "image is 64x48 but the camera_info is for 640x480"),
    ]
    before = recognizer.core.view
    for msg, key, field in bad:
        if field.startswith("image is 64x48"):  # a good CameraInfo first, for the mismatch
            pubs[CameraInfo].publish(info(640, 480, 385.0, 385.0, 319.5, 239.5))
            assert spin_until(executor, lambda: recognizer.loop.k is not None, 5)
        counts = dict(recognizer.refuse.counts)
        pubs[type(msg)].publish(msg)
        assert spin_until(executor, lambda: recognizer.refuse.counts.get(key, 0) >
                          counts.get(key, 0), 5), (key, field)
        assert field in recognizer.refuse.latest[key], recognizer.refuse.latest[key]
    assert not recognizer.loop.poses  # no bad pose reached the node's state
    assert recognizer.core.episode.steps == 0 and recognizer.core.view == before
    for name, value, why in [("object_size", 1e300, "object_size must be a finite number in"),
                             ("standoff", -1.0, "standoff must be"),
                             ("view_timeout", 0.0, "view_timeout must be"),
                             ("max_retries", -1, "max_retries must be"),
                             ("max_clock_offset", float("inf"), "max_clock_offset must be"),
                             ("min_elevation", -90.0, "read-only"),
                             ("image_qos", "reliable", "read-only")]:
        result = recognizer.set_parameters([Parameter(name, value=value)])[0]
        # outside its descriptor's range rclpy refuses it first, in its words; the log has ours
        ours = "out of range" if PARAMS[name].bounds and why != "read-only" else why
        assert not result.successful and ours in result.reason, (name, result.reason)
        if why != "read-only":  # each in the log: one refusal hides no other
            assert why in recognizer.refuse.latest[f"parameter {name}"], name
    assert recognizer.sensing.object_size == 1.0 and recognizer.loop.timing.view_timeout == 0.5
    result = recognize(executor, client)  # the simulated camera's good inputs from here on
    assert result is not None and result["status"] == sure_or_not(result, recognizer.core.confidence), result
    assert result["label"] == "bathtub"  # procedural/test[0]
    assert getattr(recognizer, "callback_errors", 0) == 0


def test_no_exception_escapes_a_callback(node):
    executor, recognizer, client, pubs = node
    observe, calls = recognizer.core.observe, []

    def broken(*args):  # a bug at the first image: the node logs it and the request is resent
        calls.append(1)
        if len(calls) == 1:
            raise RuntimeError("a bug")
        return observe(*args)
    recognizer.core.observe = broken
    result = recognize(executor, client)
    assert result is not None and result["status"] == sure_or_not(result, recognizer.core.confidence)
    assert recognizer.callback_errors == 1 and recognizer.loop.counts["resent"] >= 1
    recognizer.core.reset = lambda **kw: 1 / 0  # ~/reset itself fails: it answers so
    future = client.reset.call_async(Trigger.Request())
    assert spin_until(executor, future.done, 5) and not future.result().success
    assert recognizer.callback_errors == 2


def test_a_silent_camera_ends_the_episode_with_no_image():
    with ros_session() as (ctx, executor):
        recognizer = Recognizer(context=ctx, parameter_overrides=[
            PROCEDURAL, Parameter("view_timeout", value=0.2), Parameter("max_retries", value=1)])
        client, views = DemoClient(context=ctx), []
        client.create_subscription(PoseStamped, "next_view", views.append, 10)
        for n in (recognizer, client):
            executor.add_node(n)
        assert spin_until(executor, client.reset.service_is_ready, 10)
        result = recognize(executor, client, timeout=5)
        assert {k: v for k, v in result.items() if k != "elapsed"} == {
            "status": "no_image", "label": "", "probability": 0.0, "entropy": None, "views": 0,
            "travel": 0.0, "robot_seconds": 0.0, "view_waits": []}
        assert 4 * 0.2 <= result["elapsed"] < 5
        assert spin_until(executor, lambda: len(views) == 4, 1)  # 2 views x (1 try + 1 retry)
        positions = np.array([[v.pose.position.x, v.pose.position.y, v.pose.position.z]
                              for v in views])
        np.testing.assert_allclose(positions[0], positions[1])  # sent again ...
        np.testing.assert_allclose(positions[2], positions[3])
        assert np.linalg.norm(positions[0] - positions[2]) > 0.1  # ... then another view
        assert recognizer.loop.counts["resent"] == 2 and recognizer.loop.counts["unreachable"] == 2


def test_with_the_defaults_a_silent_camera_ends_an_episode_within_15_s():
    timeout, retries = PARAMS["view_timeout"].default, PARAMS["max_retries"].default
    assert timeout * (retries + 1) * PARAMS["max_unreachable_views"].default <= 15.0
    assert timeout >= 2.0  # and a camera that is merely slow is not given up at once


def followed(sub):
    sub.follow()
    return sub.reliability


def test_auto_qos_follows_the_publishers_as_they_come_and_change():
    from rclpy.qos import QoSProfile, ReliabilityPolicy
    from active_recognition.nodes.inputs import SensorSubscription
    with ros_session() as (ctx, executor):
        node, got = Node("listener", context=ctx), []
        sub = SensorSubscription(node, Image, "depth/image", got.append, "auto")
        fixed = SensorSubscription(node, Image, "depth/image", got.append, "reliable")
        assert sub.reliability == "best_effort"  # no publisher yet: hears any
        talker = Node("talker", context=ctx)
        for n in (node, talker):
            executor.add_node(n)
        reliable = talker.create_publisher(Image, "depth/image", QoSProfile(depth=1))
        assert spin_until(executor, lambda: followed(sub) == "reliable", 5)
        best_effort = talker.create_publisher(Image, "depth/image", QoSProfile(
            depth=1, reliability=ReliabilityPolicy.BEST_EFFORT))
        assert spin_until(executor, lambda: followed(sub) == "best_effort", 5)
        assert spin_until(executor, lambda: best_effort.get_subscription_count() == 1, 5)
        best_effort.publish(ma.metres_to_image(np.ones((4, 4), np.float32)))
        assert spin_until(executor, lambda: len(got) == 1, 5)  # the reliable one cannot hear it
        talker.destroy_publisher(best_effort)
        assert spin_until(executor, lambda: followed(sub) == "reliable", 5)
        assert not fixed.follow() and fixed.reliability == "reliable"
        assert reliable.get_subscription_count() >= 1


def test_the_simulated_camera_publishes_nothing_for_a_pose_below_its_floor():
    with ros_session() as (ctx, executor):
        camera = SimulatedCameraNode(context=ctx, parameter_overrides=[
            Parameter("floor", value=True), Parameter("index", value=3)])
        client, images = Node("arm", context=ctx), []
        client.create_subscription(Image, "depth/image", images.append, qos_profile_sensor_data)
        request = client.create_publisher(PoseStamped, "next_view", 10)
        for n in (camera, client):
            executor.add_node(n)
        assert spin_until(executor, lambda: request.get_subscription_count() > 0, 10)
        request.publish(ma.view_to_pose(2.6, 0.3, 1.5))  # from below
        assert not spin_until(executor, lambda: images, 0.5) and camera.unanswered == 1
        request.publish(ma.view_to_pose(0.6, 0.3, 1.5))  # from above
        assert spin_until(executor, lambda: images, 5) and camera.unanswered == 1
