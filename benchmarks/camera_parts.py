# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""Where the points go through the camera: the same ModelNet10 test objects, the same starts and
the same simulated camera (`realsense` by default) through the recognizer's own path, each part
of the node changed alone against the node's defaults with today's model.

Parts (rows): the model (`--other-checkpoint`, e.g. an older modelnet10.pt; it answers
`unknown` only if it carries an open_set), the `unknown` answer (off: unknown_threshold 0, no
hold), the hold alone (hold_unknown false), the size prior (use_size false, as when object_size
is a guess) and the planner (`--planners`); with `--sensor-parts`, each of the camera's defects
taken away alone (flying-pixel removal at steep edges, depth noise and millimetre steps, random
holes, the arm's pose error, the floor). Prints per row the accuracy (an `unknown` answer
wrong) with its standard error, its paired difference from the defaults' row with the paired
standard error, the share answered `unknown`, the mean views, travel and robot seconds (robot_time
defaults). Writes docs/results/modelnet10/camera_parts.json (a partial run must give --out); last
line JSON.

    python benchmarks/camera_parts.py --root ~/data/ModelNet10 --other-checkpoint OLD.pt [--planners learned]
"""
import argparse
from dataclasses import replace
from pathlib import Path

import numpy as np
from common import add_common_flags, emit, one_line_errors, output, results_dir

from active_recognition.datasets import default_cache_dir, open_dataset
from active_recognition.evaluation.camera_episodes import camera_runs, robot_cost
from active_recognition.evaluation.evaluate import EvalConfig
from active_recognition.evaluation.report import write_json
from active_recognition.model import checkpoint
from active_recognition.options.flags_and_parameters import add_flags
from active_recognition.options.recognizer_params import RecognizerParameters
from active_recognition.runtime.active_recognizer import ActiveRecognizer
from active_recognition.simulation.depth_sensor import sensor_config

OBJECTS_DEFAULT = 0  # 0: the whole test split


# the camera's defects, each taken away alone (--sensor-parts): row name -> SensorConfig changes
SENSOR_PARTS = {"camera without edge dropout": {"edge_dropout": 0.0},
                "camera without depth noise": {"noise": "none", "encoding": "32FC1"},
                "camera without random holes": {"dropout": 0.0},
                "camera without pose error": {"pose_error_deg": 0.0},
                "camera without floor": {"floor": False}}


def rows(args):
    """(name, checkpoint path, planner, sensing changes, sensor changes) of each row; the first
    is the defaults'."""
    today = checkpoint.model_path(args.checkpoint, "modelnet")
    out = [("defaults", today, "auto", {}, {}),
           ("no unknown answer", today, "auto", {"unknown_threshold": 0.0, "hold_unknown": False}, {}),
           ("no hold", today, "auto", {"hold_unknown": False}, {}),
           ("no size prior", today, "auto", {"use_size": False}, {})]
    if args.other_checkpoint:
        other = Path(args.other_checkpoint)
        out += [(f"model {other.name}", other, "auto", {}, {}),
                (f"model {other.name}, no size prior", other, "auto", {"use_size": False}, {})]
    out += [(f"planner {p}", today, p, {}, {}) for p in args.planners]
    if args.sensor_parts:
        out += [(name, today, "auto", {}, sensor) for name, sensor in SENSOR_PARTS.items()]
    return out


def measure(path, planner, changes, sensor, test, objects, args):
    node = RecognizerParameters()
    core = ActiveRecognizer(str(path), node.episode, args.seed, planner, replace(node.sensing, **changes),
                            node.limits)
    camera = sensor_config(args.camera, **sensor)
    runs = camera_runs(core, test, "modelnet", "test", objects, camera, args.seed, args.root)
    right = np.array([r.right for r in runs], dtype=float)
    return core.planner, right, {"unknown": float(np.mean([r.status == "unknown" for r in runs])), **robot_cost(runs)}


def run(ap, args):
    partial = [f for f, on in (("--objects", args.objects != OBJECTS_DEFAULT), ("--seed", args.seed),
                               ("--camera", args.camera != "realsense")) if on]
    args.out = output(ap, args.out, str(results_dir("modelnet") / "camera_parts.json"), partial)
    test = open_dataset("modelnet", args.root, "test", cache_dir=default_cache_dir())
    if not 0 <= args.objects <= len(test):
        ap.error(f"--objects must be 0 (all) to {len(test)} (the ModelNet10 test objects)")
    objects = np.sort(np.random.default_rng(args.seed).permutation(len(test))[:args.objects or len(test)])
    record = {"camera": args.camera, "objects": len(objects), "seed": args.seed,
              "episode": vars(RecognizerParameters().episode), "rows": {}}
    base = None
    for name, path, planner, changes, sensor in rows(args):
        planner, right, figures = measure(path, planner, changes, sensor, test, objects, args)
        base = right if base is None else base
        diff = right - base
        row = {"checkpoint": Path(path).name, "planner": planner, "changes": changes,
               **({"camera_changes": sensor} if sensor else {}),
               "accuracy": round(float(right.mean()), 4),
               "accuracy_se": round(float(right.std(ddof=1) / np.sqrt(len(right))), 4),
               "minus_defaults": round(float(diff.mean()), 4),
               "minus_defaults_se": round(float(diff.std(ddof=1) / np.sqrt(len(diff))), 4),
               **{k: round(v, 4) for k, v in figures.items()}}
        record["rows"][name] = row
        print(f"{name:32s} {row['accuracy']:.1%} +- {row['accuracy_se']:.1%}  vs defaults "
              f"{row['minus_defaults']:+.1%} +- {row['minus_defaults_se']:.1%}  unknown {row['unknown']:.1%}  "
              f"views {row['views']:.2f}  travel {row['travel_deg']:.0f} deg  robot s {row['robot_s']:.1f} / "
              f"p90 {row['robot_s_p90']:.1f}", flush=True)
    if args.out:
        write_json(Path(args.out), record)
    emit({name: row["accuracy"] for name, row in record["rows"].items()})


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    add_common_flags(ap, "root", "checkpoint", root_required=True)
    add_flags(ap, EvalConfig, ["seed"])
    ap.add_argument("--other-checkpoint", default=None, help="another model to set beside today's")
    ap.add_argument("--planners", nargs="*", default=[], help="planners to run beside the default")
    ap.add_argument("--objects", type=int, default=OBJECTS_DEFAULT,
                    help="ModelNet10 test objects (a seeded draw; default 0: every one)")
    ap.add_argument("--sensor-parts", action="store_true", help=(
        "add a row per defect of the camera taken away alone (edge dropout, depth noise, holes, "
        "pose error, floor)"))
    add_common_flags(ap, "camera", "out", out="docs/results/modelnet10/camera_parts.json")
    args = ap.parse_args(argv)
    with one_line_errors(ap):
        run(ap, args)


if __name__ == "__main__":
    main()
