# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""The simulated camera node's ROS parameters, each defined once, without rclpy.

`SimulatedCameraParameters` holds what the camera shows (a dataset's object: the datasets' names
and splits are its choices), the node's own settings, its frames and the sensor's (the simulated
camera's SensorConfig), nested ones flat beside the others; config/simulated_camera.yaml is
generated from them. The recognizer's parameters are in recognizer_params.py, which imports
neither datasets nor the simulated camera.
"""
from __future__ import annotations

from dataclasses import dataclass

from active_recognition.argument_checks import SEED_MAX, nested, option, validate
from active_recognition.datasets import NAMES, SPLITS
from active_recognition.simulation.depth_sensor import SensorConfig

CAMERA_QOS = ("sensor_data", "reliable")


@dataclass
class ObjectSource:
    """What the simulated camera shows (changed at run time to switch objects)."""

    mesh: str = option("", help="a mesh file (.off .obj .ply .stl .glb); empty = an object of "
                                "`dataset`")
    dataset: str = option("procedural", choices=NAMES, help="dataset whose object is shown")
    root: str = option("", help="dataset root folder (not for procedural)")
    split: str = option("test", choices=SPLITS, help="the dataset's split (cross: a generated "
                                                     "benchmark's held-out styles)")
    index: int = option(0, lo=0, help="which object of the split; change at run time to switch "
                                      "objects")

    def __post_init__(self):
        validate(self)


@dataclass
class CameraNodeConfig:
    """The simulated camera node's own settings."""

    frame_id: str = option("camera_depth_optical_frame", length=(1, None),
                           help="frame_id of the images")
    seed: int = option(0, lo=0, hi=SEED_MAX, help="seed of the noise, the dropout, the pose "
                                                  "error and the unanswered requests")
    image_qos: str = option("sensor_data", choices=CAMERA_QOS, help=(
        "reliability of its three topics: sensor_data (best effort) or reliable"))

    def __post_init__(self):
        validate(self)


@dataclass
class CameraFrames:
    """Where the simulated camera says it is: camera/pose, TF, or both."""

    publish_pose: bool = option(True, help="publish camera/pose with each image")
    publish_tf: bool = option(False, help=(
        "broadcast the camera's optical frame (frame_id) on TF with each image, stamped like it, "
        "relative to world_frame if set, else to object_frame"))
    object_frame: str = option("object", length=(1, None), help=(
        "the object's frame: requests in it are taken as they are"))
    world_frame: str = option("", help=(
        "a world frame the object stands in at object_x/y/z/yaw (a static transform on TF): "
        "requests in it are moved into the object frame; empty = none"))
    object_x: float = option(0.0, lo=-1000, hi=1000, help="metres: the object frame's origin in world_frame")
    object_y: float = option(0.0, lo=-1000, hi=1000, help="metres")
    object_z: float = option(0.0, lo=-1000, hi=1000, help="metres")
    object_yaw: float = option(0.0, lo=-360, hi=360, help="degrees: the object frame turned about world z")
    tf_delay: float = option(0.0, lo=0, hi=10, help=(
        "seconds the camera's transform is broadcast after its image (a slow TF publisher)"))

    def __post_init__(self):
        validate(self)


@dataclass
class SimulatedCameraParameters:
    """Every parameter of the simulated camera node; the sensor's default to the model's own
    virtual camera (demo --camera realsense sets simulated_camera.PRESETS['realsense'])."""

    source: ObjectSource = nested(ObjectSource, flat=True, runtime=True)
    node: CameraNodeConfig = nested(CameraNodeConfig, flat=True)
    frames: CameraFrames = nested(CameraFrames, flat=True)
    sensor: SensorConfig = nested(SensorConfig, flat=True)

    def __post_init__(self):
        validate(self)
