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

from .controller import Timing
from .datasets import NAMES, SPLITS
from .episode import EpisodeConfig
from .reach import ViewLimits
from .recognizer import NODE_PLANNERS, SensingConfig
from .simulated_camera import SensorConfig
from .validation import SEED_MAX, nested, option, validate

QOS_MODES = ("auto", "reliable", "sensor_data")
SENSING_NAMES = frozenset(f.name for f in fields(SensingConfig))
TIMING_NAMES = frozenset(f.name for f in fields(Timing))
GOAL_POLICIES = ("reject", "preempt")
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
    require_fresh_images: bool = option(True, help="ignore images stamped before the last "
                                                   "next_view request")
    pose_tolerance: float = option(0.05, lo=0, hi=60, runtime=True, help=(
        "seconds: the camera/pose nearest an image's stamp within this is its pose; an image "
        "waits this long for a late pose"))
    image_qos: str = option("auto", choices=QOS_MODES, help=(
        "reliability of depth/image, depth/camera_info, camera/pose (keep-last 1): auto = what "
        "their publishers offer (reliable if all of them do; followed when they change), "
        "reliable, or sensor_data (best effort). Best-effort frames over 512 kB from another "
        "process need config/fastdds_large_frames.xml on the camera's side"))
    view_timeout: float = option(3.0, lo=0.01, hi=3600, runtime=True, help=(
        "seconds: a next_view that no usable image answers within this is sent again"))
    max_retries: int = option(1, lo=0, hi=100, runtime=True, help=(
        "resends of one view; when they go unanswered too the view is unreachable and the "
        "planner picks another"))
    max_clock_offset: float = option(5.0, lo=0.001, hi=86400, runtime=True, help=(
        "seconds: images and poses stamped further than this from the node's clock are refused "
        "(another clock; a replay without use_sim_time)"))
    record: str = option("", help=(
        "an .mcap file: every topic of the loop is recorded to it from start to shutdown "
        "(written as a temporary file beside it and renamed on shutdown); ros2 bag play and "
        "Foxglove read it. Empty = off"))
    episode_timeout: float = option(60.0, lo=0.1, hi=86400, runtime=True, help=(
        "seconds: an episode still under way this long after its ~/reset ends with status "
        "timeout and the best guess so far (60 s: each of 10 views taking both its tries of 3 s)"))
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
    episode: EpisodeConfig = nested(EpisodeConfig, flat=True)
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
class SimulatedCameraParameters:
    """Every parameter of the simulated camera node; the sensor's default to the model's own
    virtual camera (demo --camera realsense sets simulated_camera.PRESETS['realsense'])."""

    source: ObjectSource = nested(ObjectSource, flat=True, runtime=True)
    node: CameraNodeConfig = nested(CameraNodeConfig, flat=True)
    sensor: SensorConfig = nested(SensorConfig, flat=True)

    def __post_init__(self):
        validate(self)


def changed(sensing, timing, values):
    """(sensing, timing) with the parameters in `values` ({name: checked value}) that belong to
    each (SensingConfig's; controller.Timing's) changed; sensing None stays None."""
    def update(config, keys):
        return replace(config, **{k: v for k, v in values.items() if k in keys})
    return (None if sensing is None else update(sensing, SENSING_NAMES), update(timing, TIMING_NAMES))
