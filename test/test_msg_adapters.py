# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""msg_adapters, tested with messages built in plain Python (no rclpy.init), like nav2's adapters."""
import array
import math

import numpy as np
import pytest
from conftest import import_ros

import_ros("sensor_msgs.msg")
from sensor_msgs.msg import Image  # noqa: E402

import msg_adapters as ma  # noqa: E402
from active_recognition.sensing import geometry  # noqa: E402
from active_recognition.sensing.depth_layer import CameraConfig  # noqa: E402


def depth_image(rng, h=5, w=7):
    d = rng.uniform(0.2, 2.0, (h, w)).astype(np.float32)
    d[1, 2] = np.nan
    return d


def test_32fc1_round_trip_keeps_nan(rng):
    d = depth_image(rng)
    msg = ma.metres_to_image(d, frame_id="cam")
    assert isinstance(msg.data, array.array) and msg.step == 7 * 4 and msg.encoding == "32FC1"
    np.testing.assert_array_equal(ma.image_to_metres(msg), d)


def test_16uc1_is_millimetres_with_zero_for_no_return(rng):
    d = depth_image(rng)
    back = ma.image_to_metres(ma.metres_to_image(d, encoding="16UC1"))
    assert np.isnan(back[1, 2])
    np.testing.assert_allclose(back[~np.isnan(d)], d[~np.isnan(d)], atol=0.0005 + 1e-6)


def test_row_padding_and_big_endian_are_honoured(rng):
    d = depth_image(rng)
    msg = Image(height=5, width=7, encoding="32FC1", is_bigendian=1, step=7 * 4 + 4)
    rows = [d[r].astype(">f4").tobytes() + b"\xff" * 4 for r in range(5)]
    msg.data = array.array("B", b"".join(rows))
    np.testing.assert_array_equal(ma.image_to_metres(msg), d)
    msg16 = Image(height=2, width=2, encoding="16UC1", is_bigendian=0, step=6)
    msg16.data = array.array("B", np.array([[1000, 0, 7], [2500, 1, 7]], "<u2").tobytes())
    np.testing.assert_allclose(ma.image_to_metres(msg16), [[1.0, np.nan], [2.5, 0.001]])


@pytest.mark.parametrize("change,reason", [
    (dict(encoding="rgb8"), "not a depth encoding"),
    (dict(data=array.array("B", b"\x00" * 10)), "expected height x step"),
    (dict(height=0, data=array.array("B")), "zero size"),
    (dict(height=100000, width=100000), "absurdly large"),
    (dict(step=4), "shorter than a row"),
])
def test_malformed_images_raise_one_error(rng, change, reason):
    msg = ma.metres_to_image(depth_image(rng))
    for k, v in change.items():
        setattr(msg, k, v)
    with pytest.raises(ma.AdapterError, match=reason):
        ma.image_to_metres(msg)


def test_pose_round_trip_and_optical_frame(rng):
    for t, p in rng.uniform([0, -math.pi], [math.pi, math.pi], (20, 2)):
        msg = ma.view_to_pose(t, p, radius=1.5)
        theta, phi, r = ma.pose_to_view(msg)
        np.testing.assert_allclose(geometry.camera_position(theta, phi, r),
                                   geometry.camera_position(t, p, 1.5), atol=1e-9)
        pos, rot = ma.pose_to_camera(msg)
        np.testing.assert_allclose(rot[:, 2], -pos / 1.5, atol=1e-9)  # z toward the object


def bad_pose(**kw):
    msg = ma.view_to_pose(1.0, 0.5)
    for k, v in kw.items():
        obj, field = k.split("__")
        setattr(getattr(msg.pose, obj), field, v)
    return msg


def test_transform_round_trip_against_the_pose_adapters(rng):
    """A frame's position and rotation through a TransformStamped come back as they went, and
    agree with the PoseStamped of the same pose; a slightly unnormalised quaternion (as TF may
    carry) is normalised."""
    for _ in range(5):
        theta, phi = rng.uniform(0.1, 3.0), rng.uniform(-3.0, 3.0)
        position, rotation = rng.normal(size=3), geometry.optical_rotation(theta, phi)
        msg = ma.position_to_transform(position, rotation, "world", "camera", ma.seconds_to_stamp(12.5))
        header = (msg.header.frame_id, msg.child_frame_id, ma.stamp_seconds(msg.header.stamp))
        assert header == ("world", "camera", 12.5)
        back = ma.transform_to_camera(msg.transform)
        np.testing.assert_allclose(back[0], position, atol=1e-12)
        np.testing.assert_allclose(back[1], rotation, atol=1e-9)
        pose = ma.pose_to_camera(ma.position_to_pose(position, rotation))
        np.testing.assert_allclose(back[1], pose[1], atol=1e-12)
    q = msg.transform.rotation
    q.x, q.y, q.z, q.w = 1.01 * q.x, 1.01 * q.y, 1.01 * q.z, 1.01 * q.w
    np.testing.assert_allclose(ma.transform_to_camera(msg.transform)[1], back[1], atol=1e-9)


@pytest.mark.parametrize("msg,reason", [
    (bad_pose(position__x=float("nan")), "NaN or infinite"),
    (bad_pose(orientation__w=float("inf")), "NaN or infinite"),
    (bad_pose(orientation__w=3.0), "not a unit quaternion"),
    (bad_pose(position__x=0.0, position__y=0.0, position__z=0.0), "centre"),
])
def test_malformed_poses_raise_one_error(msg, reason):
    with pytest.raises(ma.AdapterError, match=reason):
        ma.pose_to_view(msg)


def test_pose_not_looking_at_the_object_is_refused():
    msg = ma.view_to_pose(1.0, 0.5)
    o = msg.pose.orientation
    o.x, o.y, o.z, o.w = 0.0, 0.0, 0.0, 1.0
    with pytest.raises(ma.AdapterError, match="does not look at the object"):
        ma.pose_to_view(msg)
    ma.pose_to_camera(msg)  # still a valid camera pose for the simulated camera


def test_camera_info_matches_the_field_of_view_and_round_trips():
    k = CameraConfig(48, 64, fov=math.radians(90)).intrinsics()
    info = ma.camera_info(k, frame_id="cam")
    fx = info.k[0]
    assert math.isclose(2 * math.atan(64 / (2 * fx)), math.radians(90))
    assert info.k[2] == 31.5 and info.k[5] == 23.5 and info.header.frame_id == "cam"
    assert ma.camera_info_to_intrinsics(info) == k
    odd = geometry.Intrinsics(640, 480, 385.0, 390.0, 318.2, 241.7)
    assert ma.camera_info_to_intrinsics(ma.camera_info(odd)) == odd


@pytest.mark.parametrize("change, reason", [
    (dict(k=[0.0] * 9), "uncalibrated"), (dict(k=[float("nan")] + [1.0] * 8), "finite"),
    (dict(width=0), "size"), (dict(k=[-5.0, 0, 32, 0, 5, 24, 0, 0, 1]), "fx")])
def test_malformed_camera_info_raises_one_error(change, reason):
    info = ma.camera_info(CameraConfig(48, 64).intrinsics())
    for key, value in change.items():
        setattr(info, key, value)
    with pytest.raises(ma.AdapterError, match=reason):
        ma.camera_info_to_intrinsics(info)


def test_probabilities_round_trip_and_markers():
    p = np.array([0.1, 0.7, 0.2], np.float32)
    np.testing.assert_allclose(ma.probabilities_from_msg(ma.probabilities_to_msg(p)), p)
    markers = ma.view_markers([[0.5, 0.1], [1.0, 0.3]], radius=1.0).markers
    assert len(markers) == 3 and len(markers[1].points) == 2
    pt = markers[1].points[0]
    np.testing.assert_allclose([pt.x, pt.y, pt.z], geometry.camera_position(0.5, 0.1), atol=1e-9)
