# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""The simulated depth camera's core: a mesh in metres, rendered the way a real camera sees it.

`SensorConfig` says what kind of camera: its K (any size, `fov` or fx/fy/cx/cy), Kinect-style
depth noise, random and edge dropout, a working range, millimetre quantisation (16UC1), a floor
under the object (opaque from both sides; a pose below it cannot be reached), an arm that
misses the requested pose or, now and then, never gets there, and the object's size in metres.
`PRESETS` holds the model's own virtual camera and a RealSense-like one. No ROS here.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, replace
from functools import lru_cache

import numpy as np

from active_recognition.argument_checks import InputError, option, validate
from active_recognition.datasets import default_cache_dir, open_dataset
from active_recognition.sensing import geometry
from active_recognition.sensing.depth_layer import CameraConfig, DepthCamera
from active_recognition.sensing.meshes import load_mesh, yawed

NOISE = ("none", "kinect")
ENCODINGS = ("32FC1", "16UC1")


@lru_cache(maxsize=4)
def opened(dataset, split, root, cache_dir):
    """A dataset split, opened once per process (a camera that switches objects, a benchmark
    that shows a whole split, would otherwise read the split's index again for every object)."""
    return open_dataset(dataset, root, split, cache_dir=cache_dir)


def load_object(mesh="", dataset="procedural", split="test", index=0, root=""):
    """(vertices, faces, description) of a mesh file, or of item `index` of a dataset split."""
    if mesh:
        return (*load_mesh(mesh), mesh)
    ds = opened(dataset, split, root or None, default_cache_dir())
    if not 0 <= index < len(ds):
        raise InputError(f"{dataset}/{split} has {len(ds)} objects; index {index} is out of range")
    return (*ds.mesh(index), f"{dataset}/{split}[{index}] ({ds.classes[ds.items[index][1]]})")


def kinect_sigma(z):
    """Depth noise of a structured-light sensor (Nguyen et al. 2012), metres at z-depth z."""
    return 0.0012 + 0.0019 * (z - 0.4) ** 2


@dataclass(frozen=True)
class SensorConfig:
    width: int = option(64, lo=1, hi=4096, help="image width, pixels (realsense: 640)")
    height: int = option(64, lo=1, hi=4096, help="image height, pixels (realsense: 480)")
    fov: float = option(120.0, lo=0, hi=180, lo_open=True, hi_open=True,
                        help="horizontal field of view, degrees (used unless fx > 0)")
    fx: float = option(0.0, lo=0, help="focal length x, pixels; 0 = from fov, square pixels, "
                                       "centred (realsense: 385)")
    fy: float = option(0.0, lo=0, help="focal length y, pixels; 0 = fx")
    cx: float = option(0.0, lo=0, help="principal point x, pixels; 0 = the image centre")
    cy: float = option(0.0, lo=0, help="principal point y, pixels; 0 = the image centre")
    noise: str = option("none", choices=NOISE, help="depth noise: none or kinect (sigma = 0.0012 + "
                                                    "0.0019 (z - 0.4)^2 metres)")
    noise_scale: float = option(1.0, lo=0, help="multiplies the noise's sigma")
    dropout: float = option(0.0, lo=0, hi=1, hi_open=True,
                            help="share of pixels lost at random (realsense: 0.03)")
    edge_dropout: float = option(0.0, lo=0, hi=90, hi_open=True, help=(
        "degrees: drop flying pixels beside depth jumps steeper than a surface this far from "
        "face-on; 0 = off (realsense: 75)"))
    min_range: float = option(0.0, lo=0, help="metres: no return nearer (realsense: 0.2)")
    max_range: float = option(0.0, lo=0, help="metres: no return farther; 0 = none (realsense: 10)")
    encoding: str = option("32FC1", choices=ENCODINGS, help="32FC1 (metres) or 16UC1 (whole "
                                                            "millimetres, realsense)")
    floor: bool = option(False, help="an opaque plane under the object; a pose below it gets no "
                                     "image (realsense: true)")
    pose_error_deg: float = option(0.0, lo=0, hi=90, hi_open=True, help=(
        "the arm misses each requested pose by this orbit angle; camera/pose says where it went "
        "(realsense: 2)"))
    unanswered: float = option(0.0, lo=0, hi=1, help=(
        "share of requests the arm never reaches (its motion planner fails): nothing is "
        "published for them"))
    object_size: float = option(1.0, lo=0, lo_open=True,
                                help="metres: the mesh's longest bounding-box edge")

    def __post_init__(self):
        validate(self, "camera ")
        if self.max_range and self.max_range <= self.min_range:
            raise InputError(f"camera max_range ({self.max_range}) must be 0 (none) or more than "
                             f"min_range ({self.min_range})")
        self.intrinsics()  # validates the size and K

    def intrinsics(self) -> geometry.Intrinsics:
        if self.fx <= 0:
            return geometry.Intrinsics.from_fov(self.width, self.height, math.radians(self.fov))
        return geometry.Intrinsics(self.width, self.height, self.fx, self.fy or self.fx,
                                   self.cx or (self.width - 1) / 2, self.cy or (self.height - 1) / 2)


PRESETS = {
    "virtual": SensorConfig(),
    "realsense": SensorConfig(width=640, height=480, fx=385.0, fy=385.0, noise="kinect",
                              dropout=0.03, edge_dropout=75.0, min_range=0.2, max_range=10.0,
                              encoding="16UC1", floor=True, pose_error_deg=2.0),
}


def orbit(position, rotation, angle, rng):
    """Turn a camera pose about the object's centre by `angle` (radians) about a random axis
    perpendicular to its position: where an arm ends up when it misses the pose."""
    position = np.asarray(position, dtype=np.float64)
    if angle == 0:
        return position, np.asarray(rotation, dtype=np.float64)
    u = position / np.linalg.norm(position)
    axis = np.cross(u, rng.standard_normal(3))
    axis /= np.linalg.norm(axis)
    kx = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
    turn = np.eye(3) + math.sin(angle) * kx + (1 - math.cos(angle)) * kx @ kx  # Rodrigues
    return turn @ position, turn @ rotation


def edge_dropout(z, degrees, focal):
    """NaN beside a depth jump (to a 4-neighbour) steeper than a surface seen `degrees` from
    face-on by a camera of `focal` pixels: where drivers remove flying pixels."""
    threshold = math.tan(math.radians(degrees)) / focal
    pad = np.pad(z, 1, constant_values=np.nan)
    h, w = z.shape
    jump = np.zeros(z.shape, bool)
    for dr, dc in ((-1, 0), (1, 0), (0, -1), (0, 1)):
        with np.errstate(invalid="ignore"):
            jump |= np.abs(pad[1 + dr:1 + dr + h, 1 + dc:1 + dc + w] - z) > threshold * z
    return np.where(jump, np.nan, z)


class SimulatedCamera:
    def __init__(self, sensor: SensorConfig = SensorConfig(), seed=0, offset=(0.0, 0.0, 0.0),
                 yaw=0.0):
        """offset (metres): where the object's centre really is in the frame the poses use
        (a detector's error); yaw (radians): the object turned about z, its box re-fitted (a
        frame of unknown heading). The recognizer is told neither."""
        self.sensor, self.offset = sensor, np.asarray(offset, dtype=np.float64)
        self.yaw = float(yaw)
        self.k = sensor.intrinsics()
        self.rng = np.random.default_rng(seed)
        self.camera, self.description, self.floor_z = None, None, None

    def load(self, **source):
        """Switch to another object; on failure the previous one stays (the error propagates)."""
        verts, faces, description = load_object(**source)
        verts = np.asarray(verts, np.float64)
        if self.yaw:
            verts = yawed(verts, self.yaw)
        verts = verts * self.sensor.object_size + self.offset
        config = CameraConfig(self.k.height, self.k.width)
        self.camera = DepthCamera(verts, faces, config, intrinsics=self.k)
        self.description, self.floor_z = description, float(verts[:, 2].min())

    def reachable(self, position):
        """Whether the arm can take a camera to `position` (metres): not below the floor."""
        return not (self.sensor.floor and np.asarray(position, np.float64)[2] < self.floor_z)

    def capture(self, position, optical_rotation):
        """Depth at a requested pose -> (metres (H, W) NaN = no return, actual position,
        actual optical rotation): the arm's error applied, then the sensor's. None when the arm
        does not get there: a pose below the floor, or one of the `unanswered` share."""
        s = self.sensor
        if not self.reachable(position) or (s.unanswered and self.rng.random() < s.unanswered):
            return None
        position, rotation = orbit(position, optical_rotation, math.radians(s.pose_error_deg),
                                   self.rng)
        hits = self.camera.trace_poses(position[None], geometry.rotation_from_optical(rotation)[None],
                                       normals=False)  # its depth alone
        z = self.camera.zdepth(hits)[0].astype(np.float64)
        if s.floor:  # opaque from both sides: from below (an arm's error) it hides everything
            rays = self.k.rays()
            dz = (rays @ rotation.T)[..., 2]  # world z per unit of optical depth
            with np.errstate(divide="ignore", invalid="ignore"):
                t = (self.floor_z - position[2]) / dz
            z = np.minimum(z, np.where(np.isfinite(t) & (t > 0), t, np.inf))
        # flying pixels sit at the surface's real depth jumps: judged before the noise, which
        # is drawn pixel by pixel here and would make a far face-on wall look torn everywhere
        jumps = None
        if s.edge_dropout:  # (a miss is no jump: NaN compares false, as after the range cut)
            jumps = np.isnan(edge_dropout(np.where(np.isfinite(z), z, np.nan), s.edge_dropout,
                                          min(self.k.fx, self.k.fy)))
        if s.noise == "kinect":
            noise = s.noise_scale * self.rng.standard_normal(z.shape)
            seen = np.isfinite(z)
            z[seen] += kinect_sigma(z[seen]) * noise[seen]
        z[~np.isfinite(z) | (z < s.min_range) | ((z > s.max_range) if s.max_range else False)] = np.nan
        if jumps is not None:
            z[jumps] = np.nan
        if s.dropout:
            z[self.rng.random(z.shape) < s.dropout] = np.nan
        if s.encoding == "16UC1":
            z = np.round(z * 1000.0) / 1000.0
            z[z == 0] = np.nan
        return z.astype(np.float32), position, rotation


def sensor_config(preset="virtual", **changes):
    """A preset ("virtual" or "realsense") with some fields changed."""
    if preset not in PRESETS:
        raise InputError(f"camera must be one of {tuple(PRESETS)}, got {preset!r}")
    return replace(PRESETS[preset], **changes)
