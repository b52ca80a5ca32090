# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""The recognizer node's ROS parameters, each defined once, without rclpy.

`RecognizerParameters` holds the options of the core's own configs (EpisodeConfig, SensingConfig,
ViewLimits, Timing, RobotTime) and the node-only settings here, nested ones flat beside the
others. nodes/__init__.declare_parameters declares each with a descriptor (description, range,
read-only) made from its field (options.flags_and_parameters); config/recognizer.yaml is
generated from them. Imports the runtime and below only: declaring the recognizer's parameters
loads no dataset and no simulated camera (test/test_layers.py). The simulated camera's are in
camera_params.py.
"""
from __future__ import annotations

from dataclasses import dataclass, fields, replace

from active_recognition.argument_checks import InputError, SEED_MAX, checks, nested, option, validate
from active_recognition.model.episode import EpisodeConfig, ROBOT
from active_recognition.runtime.active_recognizer import NODE_PLANNERS, SensingConfig
from active_recognition.runtime.robot_time import RobotTime
from active_recognition.runtime.timing import Timing
from active_recognition.sensing.reach import ViewLimits

QOS_MODES = ("auto", "reliable", "sensor_data")
GOAL_POLICIES = ("reject", "preempt")
POSE_SOURCES = ("topic", "tf")


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


def changed(values, *configs):
    """Each of `configs` (dataclasses) with the parameters in `values` ({name: checked value})
    that are its fields changed (each validates itself)."""
    return tuple(replace(c, **{k: v for k, v in values.items() if k in {f.name for f in fields(c)}})
                 for c in configs)


def check_goal(object_size=0.0, max_views=0, time_budget=0.0):
    """Refuse (InputError) a goal's object_size, max_views or time_budget outside its parameter's
    range (0 keeps the node's parameter)."""
    for name, value, config, unit in (("time_budget", time_budget, Timing, " robot seconds"),
                                      ("object_size", object_size, SensingConfig, " m"),
                                      ("max_views", max_views, EpisodeConfig, "")):
        check = checks(config)[name]
        if not (value == 0 or check.lo <= value <= check.hi):  # NaN too
            lo = "" if check.lo == 0 else f" or {check.lo:g}"
            raise InputError(f"{name} must be 0 (the node's){lo} to {check.hi:g}{unit}, got {value}")
