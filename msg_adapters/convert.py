# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""Typed, pure conversions between standard ROS messages and numpy arrays or views.

Depth images follow REP 118: 32FC1 in metres (NaN = no return) or 16UC1 in millimetres
(0 = no return). Poses are camera optical frames (x right, y down, z forward; REP 103) in the
object frame, whose origin is the object's centre.
"""
from __future__ import annotations

import array
import math

import numpy as np
from geometry_msgs.msg import PoseStamped
from sensor_msgs.msg import CameraInfo, Image
from std_msgs.msg import Float32MultiArray, MultiArrayDimension

from active_recognition.sensing import geometry

MAX_PIXELS = 4096 * 4096
ENCODINGS = {"32FC1": (np.float32, 4), "16UC1": (np.uint16, 2)}


class AdapterError(ValueError):
    """A message that cannot be converted; the message says which field and why."""


def image_to_metres(msg: Image) -> np.ndarray:
    """sensor_msgs/Image (32FC1 or 16UC1) -> (H, W) float32 metres, NaN where no return.

    Honours row padding (`step`) and `is_bigendian`. Raises AdapterError on a malformed image.
    """
    if msg.encoding not in ENCODINGS:
        raise AdapterError(f"image encoding {msg.encoding!r} is not a depth encoding "
                           f"(use {' or '.join(ENCODINGS)})")
    dtype, size = ENCODINGS[msg.encoding]
    h, w, step = int(msg.height), int(msg.width), int(msg.step)
    if h == 0 or w == 0:
        raise AdapterError(f"image has zero size ({h}x{w})")
    if h * w > MAX_PIXELS:
        raise AdapterError(f"image of {h}x{w} pixels is absurdly large (max {MAX_PIXELS})")
    if step < w * size:
        raise AdapterError(f"image step {step} is shorter than a row of {w} x {size} bytes")
    if len(msg.data) != h * step:
        raise AdapterError(f"image data has {len(msg.data)} bytes, expected height x step = {h * step}")
    raw = np.frombuffer(bytes(msg.data) if not isinstance(msg.data, (bytes, array.array))
                        else msg.data, dtype=np.uint8).reshape(h, step)[:, :w * size]
    order = ">" if msg.is_bigendian else "<"
    values = raw.copy().view(np.dtype(dtype).newbyteorder(order)).reshape(h, w)
    if msg.encoding == "16UC1":
        out = values.astype(np.float32) / 1000.0
        out[values == 0] = np.nan
        return out
    out = values.astype(np.float32)
    out[~np.isfinite(out) | (out <= 0)] = np.nan  # REP 118: NaN/inf/non-positive = no return
    return out


def metres_to_image(depth, stamp=None, frame_id="", encoding="32FC1") -> Image:
    """(H, W) metres (NaN = no return) -> sensor_msgs/Image, 32FC1 or 16UC1 (little-endian)."""
    depth = np.asarray(depth, dtype=np.float32)
    if depth.ndim != 2:
        raise AdapterError(f"depth must be (H, W), got shape {depth.shape}")
    msg = Image()
    if stamp is not None:
        msg.header.stamp = stamp
    msg.header.frame_id = frame_id
    msg.height, msg.width = depth.shape
    msg.encoding, msg.is_bigendian = encoding, 0
    if encoding == "32FC1":
        arr = depth.astype("<f4")
    elif encoding == "16UC1":
        mm = np.where(np.isfinite(depth), np.round(depth * 1000.0), 0)
        arr = np.clip(mm, 0, 65535).astype("<u2")
    else:
        raise AdapterError(f"cannot write depth as {encoding!r} (use 32FC1 or 16UC1)")
    msg.step = msg.width * arr.itemsize
    msg.data = array.array("B", arr.tobytes())  # the fast path of the generated setter
    return msg


def camera_info(k: geometry.Intrinsics, stamp=None, frame_id="") -> CameraInfo:
    """CameraInfo of a rectified pinhole camera (geometry.Intrinsics): no distortion."""
    fx, fy, cx, cy = k.fx, k.fy, k.cx, k.cy
    msg = CameraInfo()
    if stamp is not None:
        msg.header.stamp = stamp
    msg.header.frame_id = frame_id
    msg.height, msg.width = k.height, k.width
    msg.distortion_model = "plumb_bob"
    msg.d = [0.0] * 5
    msg.k = [fx, 0.0, cx, 0.0, fy, cy, 0.0, 0.0, 1.0]
    msg.r = [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0]
    msg.p = [fx, 0.0, cx, 0.0, 0.0, fy, cy, 0.0, 0.0, 0.0, 1.0, 0.0]
    return msg


def camera_info_to_intrinsics(msg: CameraInfo) -> geometry.Intrinsics:
    """CameraInfo -> geometry.Intrinsics (its K; the image is taken as rectified).

    Raises AdapterError on an uncalibrated (all-zero) or malformed K, or a zero image size.
    """
    k = np.asarray(msg.k, dtype=np.float64)
    if k.shape != (9,) or not np.all(np.isfinite(k)):
        raise AdapterError("camera_info K must hold 9 finite numbers")
    if not k.any():
        raise AdapterError("camera_info K is all zeros: the camera is uncalibrated")
    if k[6] != 0 or k[7] != 0 or k[8] != 1 or k[3] != 0:
        raise AdapterError(f"camera_info K must be [fx 0 cx, 0 fy cy, 0 0 1]; its k[3], k[6], k[7] "
                           f"and k[8] are {k[3]:g}, {k[6]:g}, {k[7]:g} and {k[8]:g}")
    try:
        return geometry.Intrinsics(int(msg.width), int(msg.height), k[0], k[4], k[2], k[5])
    except ValueError as e:
        raise AdapterError(f"camera_info: {e}") from None


def stamp_seconds(stamp) -> float:
    """builtin_interfaces/Time -> seconds."""
    return stamp.sec + stamp.nanosec * 1e-9


def seconds_to_stamp(seconds: float):
    """Seconds (>= 0) -> builtin_interfaces/Time, to the nearest nanosecond."""
    from builtin_interfaces.msg import Time

    sec, nanosec = divmod(round(seconds * 1e9), 1_000_000_000)
    return Time(sec=int(sec), nanosec=int(nanosec))


def view_to_pose(theta, phi, radius=1.0, frame_id="object", stamp=None) -> PoseStamped:
    """A view on the sphere -> the camera's optical-frame pose in the object frame."""
    return position_to_pose(geometry.camera_position(float(theta), float(phi), radius),
                            geometry.optical_rotation(float(theta), float(phi)), frame_id, stamp)


def position_to_pose(position, optical_rotation, frame_id="object", stamp=None) -> PoseStamped:
    """A camera position (3,) and optical rotation (3, 3) -> PoseStamped."""
    msg = PoseStamped()
    msg.header.frame_id = frame_id
    if stamp is not None:
        msg.header.stamp = stamp
    p, o = msg.pose.position, msg.pose.orientation
    p.x, p.y, p.z = (float(v) for v in position)
    o.x, o.y, o.z, o.w = (float(v) for v in geometry.matrix_to_quaternion(optical_rotation))
    return msg


def position_to_transform(position, rotation, parent, child, stamp=None):
    """A frame's position (3,) and rotation (3, 3) in `parent` -> geometry_msgs/TransformStamped
    of frame `child` (what a TF broadcaster sends)."""
    from geometry_msgs.msg import TransformStamped

    msg = TransformStamped()
    msg.header.frame_id, msg.child_frame_id = parent, child
    if stamp is not None:
        msg.header.stamp = stamp
    t, r = msg.transform.translation, msg.transform.rotation
    t.x, t.y, t.z = (float(v) for v in position)
    r.x, r.y, r.z, r.w = (float(v) for v in geometry.matrix_to_quaternion(rotation))
    return msg


def transform_to_camera(transform):
    """geometry_msgs/Transform (as tf2 gives it) -> (position (3,), rotation (3, 3)) of the frame
    it maps from; the quaternion normalised."""
    t, q = transform.translation, transform.rotation
    q = np.array([q.x, q.y, q.z, q.w], dtype=np.float64)
    return np.array([t.x, t.y, t.z], dtype=np.float64), geometry.quaternion_to_matrix(q / np.linalg.norm(q))


def pose_to_camera(msg: PoseStamped):
    """PoseStamped -> (position (3,), optical rotation (3, 3)); any pose, validated."""
    p, o = msg.pose.position, msg.pose.orientation
    pos = np.array([p.x, p.y, p.z], dtype=np.float64)
    q = np.array([o.x, o.y, o.z, o.w], dtype=np.float64)
    if not (np.all(np.isfinite(pos)) and np.all(np.isfinite(q))):
        raise AdapterError("pose has NaN or infinite values")
    norm = np.linalg.norm(q)
    if abs(norm - 1.0) > 1e-3:
        raise AdapterError(f"pose orientation is not a unit quaternion (norm {norm:.4f})")
    return pos, geometry.quaternion_to_matrix(q / norm)


def pose_to_view(msg: PoseStamped, tolerance_deg=2.0):
    """PoseStamped on the viewing sphere -> (theta, phi, radius).

    Raises AdapterError unless the optical z axis points at the object's centre (within
    `tolerance_deg`).
    """
    pos, rot = pose_to_camera(msg)
    try:
        radius, theta, phi = geometry.view_from_position(pos)
    except ValueError as e:
        raise AdapterError(f"pose: {e}") from None
    angle = math.degrees(math.acos(np.clip(rot[:, 2] @ (-pos / radius), -1, 1)))
    if angle > tolerance_deg:
        raise AdapterError(f"pose does not look at the object: optical axis {angle:.1f} deg off")
    return theta, phi, radius


def probabilities_to_msg(probs) -> Float32MultiArray:
    probs = np.asarray(probs, dtype=np.float32).ravel()
    msg = Float32MultiArray()
    msg.layout.dim = [MultiArrayDimension(label="class", size=len(probs), stride=len(probs))]
    msg.data = probs.tolist()
    return msg


def probabilities_from_msg(msg: Float32MultiArray) -> np.ndarray:
    data = np.asarray(msg.data, dtype=np.float32)
    if data.ndim != 1 or len(data) == 0 or not np.all(np.isfinite(data)):
        raise AdapterError("probabilities must be a non-empty finite vector")
    return data


def view_markers(views, radius, frame_id="object", stamp=None):
    """visualization_msgs/MarkerArray: the viewing sphere, the views taken and their path."""
    from geometry_msgs.msg import Point
    from visualization_msgs.msg import Marker, MarkerArray

    def marker(mid, kind, ns):
        m = Marker()
        m.header.frame_id = frame_id
        if stamp is not None:
            m.header.stamp = stamp
        m.ns, m.id, m.type, m.action = ns, mid, kind, Marker.ADD
        m.pose.orientation.w = 1.0
        return m

    sphere = marker(0, Marker.SPHERE, "sphere")
    sphere.scale.x = sphere.scale.y = sphere.scale.z = 2.0 * radius
    sphere.color.r = sphere.color.g = sphere.color.b = 0.7
    sphere.color.a = 0.15
    views = np.asarray(views, dtype=np.float64).reshape(-1, 2)
    pts = [Point(x=float(x), y=float(y), z=float(z))
           for x, y, z in geometry.camera_position(views[:, 0], views[:, 1], radius)]
    dots = marker(1, Marker.SPHERE_LIST, "views")
    dots.scale.x = dots.scale.y = dots.scale.z = 0.05 * radius
    dots.color.r, dots.color.a = 1.0, 1.0
    dots.points = pts
    path = marker(2, Marker.LINE_STRIP, "path")
    path.scale.x = 0.01 * radius
    path.color.b, path.color.a = 1.0, 1.0
    path.points = pts if len(pts) > 1 else []
    return MarkerArray(markers=[sphere, dots, path])
