# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""The options of the small subcommands (render, dataset, demo, recognize), from which cli.py's flags are
generated; train and evaluate take TrainConfig's and EvalConfig's."""
from __future__ import annotations

import math
from dataclasses import dataclass

from active_recognition.argument_checks import SEED_MAX, option
from active_recognition.datasets import NAMES
from active_recognition.model.episode import MAX_VIEWS
from active_recognition.runtime.active_recognizer import NODE_PLANNERS

SEED = dict(lo=0, hi=SEED_MAX)


@dataclass
class RenderOptions:
    mesh: str | None = option(None, kind=str, optional=True, required=True,
                              help="mesh file (.off .obj .ply .stl .glb)")
    theta: float = option(math.radians(60), help="polar angle, radians")
    phi: float = option(math.radians(30), help="azimuth, radians")
    views: int = option(0, lo=0, hi=100, help="render this many evenly spread views instead of one")
    size: int = option(64, lo=1, hi=1024, help="image height and width in pixels")
    radius: float = option(1.0, lo=0, lo_open=True, hi=100, help="viewing-sphere radius R")
    fov: float | None = option(None, kind=float, optional=True, lo=0, hi=180, lo_open=True,
                               hi_open=True, help=("field of view in degrees (default: holds the "
                                                   "[-0.5, 0.5]^3 cube)"))
    out: str = option("depth.png", help="output PNG")


@dataclass
class DatasetOptions:
    name: str = option("procedural", choices=NAMES, help="dataset layout")
    root: str | None = option(None, kind=str, optional=True,
                              help="dataset root folder (not for procedural)")
    cache_dir: str | None = option(None, kind=str, optional=True, exclusive="cache", help=(
        "where parsed meshes are cached (default ~/.cache/active_recognition)"))
    no_cache: bool = option(False, exclusive="cache", help="do not read or write the cache")
    contact_sheet: str | None = option(None, kind=str, optional=True,
                                       help="write a PNG grid of test-split depth images")
    sheet_split: str = option("test", choices=("test", "cross"), help=(
        "the split on the sheet (cross: a generated benchmark's held-out styles)"))
    objects_per_class: int = option(2, lo=1, hi=20, help="objects per class on the sheet")
    views_per_object: int = option(3, lo=1, hi=5, help=(
        "views per object on the sheet (front, side, top, below, three-quarter)"))
    seed: int = option(0, **SEED, help="which objects go on the sheet")


@dataclass
class DemoOptions:
    objects: int = option(10, lo=1, hi=100_000, help="test objects to recognise")
    dataset: str = option("procedural", choices=("procedural", "twins"),
                          help="embedded dataset whose test objects the simulated camera shows")
    seed: int = option(0, **SEED, help="which objects and initial views")
    checkpoint: str | None = option(None, kind=str, optional=True,
                                    help="model file (default: the dataset's shipped model)")
    planner: str = option("auto", choices=NODE_PLANNERS,
                          help="next-view planner (auto: the model's best, as measured)")
    camera: str = option("virtual", choices=("virtual", "realsense"), help=(
        "simulated camera: the model's own (64x64, 120 degrees), or RealSense-like (640x480, "
        "fx = fy = 385, Kinect noise, 3 % dropout, flying pixels removed, a floor, 2 degrees of "
        "pose error)"))
    time_budget: float = option(0.0, lo=0, hi=86400, help=(
        "robot seconds each object's views may cost (the recognizer's time_budget; 0 = none)"))
    record: str | None = option(None, kind=str, optional=True, metavar="FILE.mcap", help=(
        "record every topic of the loop to this MCAP file (ros2 bag play, Foxglove)"))


@dataclass
class RecognizeOptions:
    action: str = option("/recognize", length=(1, None), help="the recognizer's action")
    object_frame: str = option("", help="the object's frame (empty: the node's frame_id)")
    object_size: float = option(0.0, lo=0, hi=100, help=(
        "metres, the longest edge of the object's box (0: the node's object_size)"))
    max_views: int = option(0, lo=0, hi=MAX_VIEWS, help="views at most (0: the node's max_views)")
    time_budget: float = option(0.0, lo=0, hi=86400, help=(
        "robot seconds the views may cost (0: the node's time_budget); the node answers before "
        "the next view would overrun it"))
    timeout: float = option(10.0, lo=0.1, hi=86400, help=(
        "seconds to wait for the action server to appear"))


@dataclass
class EvaluateRuns:
    """evaluate's training curves, beside EvalConfig (they go into the report)."""

    learned_metrics: str | None = option(None, kind=str, optional=True,
                                         help="metrics.csv of the learned run")
    reinforce_metrics: str | None = option(None, kind=str, optional=True,
                                           help="metrics.csv of the reinforce run")
