# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""Poses from TF (pose_source: tf) and next_view in a planning frame, in one process: the
simulated camera broadcasts its optical frame and publishes no camera/pose. Across processes at
640x480: test_cross_process_tf.py."""
import math

import numpy as np
import pytest

from conftest import import_ros, need_tf2, sure_or_not

rclpy = import_ros("rclpy")
need_tf2()
from geometry_msgs.msg import PoseStamped  # noqa: E402
from rclpy.parameter import Parameter  # noqa: E402

import msg_adapters as ma  # noqa: E402
from active_recognition.model.checkpoint import shipped  # noqa: E402
from active_recognition.nodes.demo import DemoClient, recognize, ros_session, spin_until  # noqa: E402
from active_recognition.nodes.recognizer import Recognizer  # noqa: E402
from active_recognition.nodes.simulated_camera import SimulatedCameraNode  # noqa: E402


def session(recognizer=None, camera=None):
    """A recognizer and the simulated camera on TF, with a DemoClient and next_view recorded."""
    ctx_session = ros_session()
    ctx, executor = ctx_session.__enter__()
    rec = Recognizer(context=ctx, parameter_overrides=[Parameter(k, value=v) for k, v in {
        "checkpoint": str(shipped("procedural")), "seed": 5, "pose_source": "tf", "view_timeout": 1.0,
        **(recognizer or {})}.items()])
    cam = SimulatedCameraNode(context=ctx, parameter_overrides=[Parameter(k, value=v) for k, v in {
        "publish_tf": True, "publish_pose": False, "index": 2, "pose_error_deg": 5.0, **(camera or {})}.items()])
    client, views = DemoClient(context=ctx), []
    client.create_subscription(PoseStamped, "next_view", views.append, 100)
    for n in (rec, cam, client):
        executor.add_node(n)
    assert spin_until(executor, client.reset.service_is_ready, 10)
    return ctx_session, executor, rec, cam, client, views


@pytest.fixture
def loop():
    made = []

    def make(**kwargs):
        made.append(session(**kwargs))
        return made[-1][1:]
    yield make
    for m in made:
        m[0].__exit__(None, None, None)


def test_every_image_takes_its_pose_from_tf(loop):
    executor, rec, cam, client, views = loop()
    for index in (2, 9):
        cam.set_parameters([Parameter("index", value=index)])
        result = recognize(executor, client)
        assert result["status"] == sure_or_not(result, rec.core.confidence), result
    n = rec.loop.counts
    assert n["classified"] >= 2 and n["matched"] == n["classified"] and n["rejected"] == 0
    assert rec.refuse.counts.get("pose_wait", 0) == 0


def test_the_view_taken_is_the_transform_not_the_request(loop):
    """The camera misses each request by its 5 degrees of arm error: the view the episode records
    is where TF says the camera was."""
    executor, rec, cam, client, views = loop(recognizer={"max_views": 2, "recentre": 0.0})
    assert recognize(executor, client)["views"] == 2
    asked = np.array([ma.pose_to_view(v, tolerance_deg=90)[:2] for v in views[:2]])
    taken = rec.core.views_taken()
    assert 0.5 < np.degrees(np.max(np.abs(np.asarray(taken) - asked))) < 15


def test_a_transform_that_never_comes_refuses_the_image_by_name(loop):
    # the object frame is on TF (world -> object, latched), the camera's frame never
    executor, rec, cam, client, views = loop(recognizer={"pose_wait": 0.2, "max_retries": 0},
                                             camera={"publish_tf": False, "world_frame": "world"})
    result = recognize(executor, client, timeout=30)
    assert result["status"] == "no_image" and result["views"] == 0  # its usual status
    assert rec.loop.counts["rejected"] >= 2 and rec.loop.counts["classified"] == 0
    why = rec.refuse.latest["depth/image"]
    assert "no transform camera_depth_optical_frame -> object (" in why and "within pose_wait (0.2 s)" in why


def test_images_refused_for_want_of_a_transform_turn_diagnostics_warn_then_error_naming_tf(loop):
    from diagnostic_msgs.msg import DiagnosticArray
    from std_srvs.srv import Trigger

    executor, rec, cam, client, views = loop(recognizer={"pose_wait": 0.2, "view_timeout": 0.5},
                                             camera={"publish_tf": False, "world_frame": "world"})
    got = []
    client.create_subscription(DiagnosticArray, "/diagnostics", lambda a: got.extend(
        s for s in a.status if s.name.endswith("recognizer: recognition")), 50)
    levels = lambda: [ma.level_name(s) for s in got]  # noqa: E731
    client.reset.call_async(Trigger.Request())
    assert spin_until(executor, lambda: "ERROR" in levels(), 30), [s.message for s in got]
    assert "WARN" in levels()[:levels().index("ERROR")]  # WARN first
    for s in got:
        if ma.level_name(s) != "OK":
            assert s.message.startswith("TF: ") and "camera_depth_optical_frame -> object" in s.message, s.message
            assert "silent" not in s.message
    assert "TF had no transform" in rec.refuse.latest["view_timeout"]  # not the camera's silence


def test_an_object_frame_tf_never_had_ends_the_episode_no_frame_within_pose_wait(loop):
    executor, rec, cam, client, views = loop(recognizer={"pose_wait": 0.3, "frame_id": "nowhere"})
    result = recognize(executor, client, timeout=20)
    assert result["status"] == "no_frame" and result["views"] == 0 and result["label"] == ""
    assert 0.3 < result["elapsed"] < 0.3 + 5.0  # at the first tick past pose_wait (a busy machine's: late)
    assert "TF has never had the object frame 'nowhere'" in rec.refuse.latest["no_frame"]


def test_a_transform_30_ms_late_is_waited_for(loop):
    executor, rec, cam, client, views = loop(camera={"tf_delay": 0.03})
    result = recognize(executor, client)
    assert result["status"] == sure_or_not(result, rec.core.confidence)
    assert rec.loop.counts["matched"] == rec.loop.counts["classified"] > 0


def test_next_view_in_a_planning_frame_is_the_object_frames_moved_by_the_objects_pose(loop):
    """The object stands in world at (1.0, -2.0, 0.5), turned 30 degrees: every next_view in world
    is the core's requested pose moved by that transform, computed here by hand."""
    place = {"world_frame": "world", "object_x": 1.0, "object_y": -2.0, "object_z": 0.5, "object_yaw": 30.0}
    executor, rec, cam, client, views = loop(recognizer={"planning_frame": "world", "max_views": 3}, camera=place)
    requested = []
    publish = rec.outputs.pubs["view"].publish
    rec.outputs.pubs["view"].publish = lambda msg: (requested.append(rec.core.requested_pose(rec.loop.k)),
                                                    publish(msg))
    result = recognize(executor, client)
    assert result["status"] == sure_or_not(result, rec.core.confidence)
    c, s = math.cos(math.radians(30)), math.sin(math.radians(30))
    rz, t = np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]]), np.array([1.0, -2.0, 0.5])
    assert len(views) == len(requested) >= 2 and {v.header.frame_id for v in views} == {"world"}
    for msg, (position, rotation) in zip(views, requested):
        got_position, got_rotation = ma.pose_to_camera(msg)
        np.testing.assert_allclose(got_position, rz @ position + t, atol=1e-6)
        np.testing.assert_allclose(got_rotation, rz @ rotation, atol=1e-6)
    n = rec.loop.counts
    assert n["matched"] == n["classified"] == 3  # the camera answered in world, TF said where


def test_without_tf2_ros_the_node_says_how_to_get_it(monkeypatch):
    import builtins

    from active_recognition.argument_checks import InputError
    from active_recognition.nodes import tf_poses

    real = builtins.__import__
    monkeypatch.setattr(builtins, "__import__", lambda name, *a, **k: (_ for _ in ()).throw(
        ImportError("No module named 'tf2_ros'")) if name == "tf2_ros" else real(name, *a, **k))
    with pytest.raises(InputError, match="pose_source: tf and planning_frame need tf2_ros.*build_interfaces.sh"):
        tf_poses.imported_tf2()


def test_with_tf_a_camera_pose_topic_is_not_read_and_the_refusal_names_the_frames(loop):
    """A camera that publishes camera/pose and no TF: pose_source tf does not take the topic's
    poses (a relay left from before would otherwise pass for TF); each image is refused with
    tf2's reason, and /diagnostics counts it unmatched."""
    executor, rec, cam, client, views = loop(recognizer={"pose_wait": 0.2, "max_retries": 0},
                                             camera={"publish_tf": False, "publish_pose": True,
                                                     "world_frame": "world"})  # the object frame on TF
    assert [s.topic for s in rec.inputs] == ["/depth/camera_info", "/depth/image"]
    result = recognize(executor, client, timeout=30)
    assert result["status"] == "no_image" and rec.loop.counts["matched"] == 0
    why = rec.refuse.latest["depth/image"]
    assert "transform camera_depth_optical_frame -> object" in why and "does not exist" in why, why
    values = rec.loop.report(rec.now())[2]
    assert values["images matched to a measured pose (%)"] == 0.0 and rec.loop.counts["unmatched"] >= 2
