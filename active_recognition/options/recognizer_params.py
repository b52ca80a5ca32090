# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""The ROS parameters of the two nodes, each defined once, without rclpy.

A node's parameters are the options of one dataclass (`RecognizerParameters`,
`SimulatedCameraParameters`), nested ones flat beside the others: the core's own configs
(EpisodeConfig, SensingConfig, ViewLimits, SensorConfig) and the node-only settings here.
nodes/__init__.declare_parameters declares each with a descriptor (description, range,
read-only) made from its field (options.parameters); config/*.yaml is generated from them.
"""
from __future__ import annotations

from dataclasses import dataclass, fields, replace

from active_recognition.argument_checks import SEED_MAX, nested, option, validate
from active_recognition.datasets import NAMES, SPLITS
from active_recognition.model.episode import EpisodeConfig, ROBOT
from active_recognition.runtime.active_recognizer import NODE_PLANNERS, SensingConfig
from active_recognition.runtime.controller import Timing
from active_recognition.runtime.robot_time import RobotTime
from active_recognition.sensing.reach import ViewLimits
from active_recognition.simulation.depth_sensor import SensorConfig

QOS_MODES = ("auto", "reliable", "sensor_data")
GOAL_POLICIES = ("reject", "preempt")
POSE_SOURCES = ("topic", "tf")
CAMERA_QOS = ("sensor_data", "reliable")


@dataclass
class NodeConfig:
    """The recognizer node's own settings (the core's configs hold the rest)."""

    checkpoint: str = option("", help=(
        "model file; empty = the shipped ModelNet10 model (modelnet10.pt, real furniture); "
        "procedural.pt for the embedded generated shapes"))
    planner: str = option("auto", choices=NODE_PLANNERS, help=(
        "next views: auto = the checkpoint's best planner, chosen on the validation split "
        "(docs/RESULTS.md), or one by name"))
    seed: int = option(0, lo=0, hi=SEED_MAX, help="seed of the random initial view (one of 50 "
                                                  "evenly spread)")
    frame_id: str = option("object", length=(1, None), help=(
        "frame of next_view: the object's, origin at its box's centre, z up"))
    image_qos: str = option("auto", choices=QOS_MODES, help=(
        "reliability of depth/image, depth/camera_info, camera/pose (keep-last 1): auto = what "
        "their publishers offer (reliable if all of them do; followed when they change; "
        "camera/pose best effort, its late poses asked again: pose_reask), "
        "reliable, or sensor_data (best effort). Best-effort frames over 512 kB from another "
        "process need config/fastdds_large_frames.xml on the camera's side"))
    record: str = option("", help=(
        "an .mcap file: every topic of the loop is recorded to it from start to shutdown "
        "(written as a temporary file beside it and renamed on shutdown); ros2 bag play and "
        "Foxglove read it. Empty = off"))
    pose_source: str = option("topic", choices=POSE_SOURCES, help=(
        "where each image's camera pose comes from: topic (camera/pose, stamped like the image) "
        "or tf (the transform from the image's frame_id to the object frame at its stamp)"))
    planning_frame: str = option("", help=(
        "frame next_view is published in (a motion planner's, e.g. world), through TF; empty = "
        "the object frame"))
    goal_policy: str = option("reject", choices=GOAL_POLICIES, help=(
        "a recognize goal that comes while another runs: reject (the running one goes on) or "
        "preempt (the running one ends canceled, its goal aborted); ~/reset always preempts"))
    autostart: bool = option(True, help=(
        "configure and activate at start, as a plain node does; false: a lifecycle manager "
        "drives it (configure, activate)"))

    def __post_init__(self):
        validate(self)


@dataclass
class RecognizerParameters:
    """Every parameter of the recognizer node."""

    node: NodeConfig = nested(NodeConfig, flat=True)
    timing: Timing = nested(Timing, flat=True)
    robot: RobotTime = nested(RobotTime, flat=True)
    episode: EpisodeConfig = nested(EpisodeConfig, ROBOT, flat=True)  # a robot pays for travel in seconds
    sensing: SensingConfig = nested(SensingConfig, flat=True, runtime=True)
    # a robot sees an object on a floor or a table from above its centre
    limits: ViewLimits = nested(ViewLimits, ViewLimits(0.0, 90.0), flat=True)

    def __post_init__(self):
        validate(self)


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


def changed(values, *configs):
    """Each of `configs` (dataclasses) with the parameters in `values` ({name: checked value})
    that are its fields changed (each validates itself)."""
    return tuple(replace(c, **{k: v for k, v in values.items() if k in {f.name for f in fields(c)}})
                 for c in configs)
