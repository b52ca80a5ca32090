# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""The shipped model through a real-looking camera: one row per way a camera differs from the
model's own, each through the ROS-free path the recognizer node uses (SimulatedCamera ->
ActiveRecognizer.observe, which reprojects into the model's camera), with the same test objects,
starts and random draws in every row. Views keep to the recognizer's default limits (nothing
from below the object's support: elevation 0..90 degrees), and the `floor` rows' floor is opaque
from both sides; a request the simulated arm cannot reach is given up (view_unreachable). Each
object is shown at its own size where the dataset knows it (ModelNet10: inches, kept within 0.3 to
3 m), and the recognizer is told that size (`object_size`, which modelnet10.pt's size prior reads);
else at 1 m.

Columns: accuracy after 3 views (the answer after the 3rd view, or at the stop if the episode
stopped sooner: what a robot allowed 3 views would say), accuracy at the stop, mean views.
Writes docs/results/camera_robustness.json and re-renders docs/RESULTS.md; a run of fewer objects,
other rows, seed or model must name its own --out. Last line is JSON:
{"clean": a, "realsense": b, "rows": {name: {"acc_3", "acc_stop", "mean_views"}}}.
"""
import argparse
import json
import multiprocessing
from concurrent.futures import ProcessPoolExecutor
from dataclasses import replace
from pathlib import Path

import numpy as np
from common import RESULTS, add_common_flags, committed, one_line_errors, output, results_dir
from results_page import write_results_page
from tqdm import tqdm

from active_recognition.datasets import default_cache_dir, open_dataset
from active_recognition.evaluation.camera_episodes import shown_size
from active_recognition.evaluation.evaluate import EvalConfig
from active_recognition.evaluation.report import write_json
from active_recognition.model import checkpoint
from active_recognition.model.episode import EpisodeConfig
from active_recognition.options.flags_and_parameters import add_flags
from active_recognition.runtime.active_recognizer import ActiveRecognizer, SensingConfig
from active_recognition.sensing.reach import ViewLimits
from active_recognition.simulation.depth_sensor import SimulatedCamera, sensor_config

OBJECTS_DEFAULT = 200  # test objects of the committed tables
# the recognizer node's default: nothing from below the object's support (an opaque floor)
LIMITS = ViewLimits(0.0, 90.0)
# name: (camera preset and changes, the recognizer's object_size belief, centre offset x size)
ROWS = {
    "clean": ({}, 1.0, 0.0),
    "kinect noise x1": ({"noise": "kinect"}, 1.0, 0.0),
    "kinect noise x3": ({"noise": "kinect", "noise_scale": 3.0}, 1.0, 0.0),
    "mm quantisation (16UC1)": ({"encoding": "16UC1"}, 1.0, 0.0),
    "dropout 10 %": ({"dropout": 0.1}, 1.0, 0.0),
    "dropout 30 %": ({"dropout": 0.3}, 1.0, 0.0),
    "edge dropout (75 deg)": ({"edge_dropout": 75.0}, 1.0, 0.0),
    "480x640, same 120-degree FOV": ({"width": 640, "height": 480}, 1.0, 0.0),
    "60-degree lens, auto standoff": ({"fov": 60.0}, 1.0, 0.0),
    "87-degree lens, auto standoff": ({"fov": 87.0}, 1.0, 0.0),
    "pose error 2 deg": ({"pose_error_deg": 2.0}, 1.0, 0.0),
    "pose error 5 deg": ({"pose_error_deg": 5.0}, 1.0, 0.0),
    "floor": ({"floor": True}, 1.0, 0.0),
    "object frame 5 % off centre": ({}, 1.0, 0.05),
    "object frame 15 % off centre": ({}, 1.0, 0.15),
    "object_size 15 % too large": ({}, 1.15, 0.0),
    "object_size 15 % too small": ({}, 0.85, 0.0),
    "realsense": ("realsense", 1.0, 0.0),
    "yaw unknown": ({}, 1.0, 0.0),
    "cross-style (held-out styles)": ({}, 1.0, 0.0),
}
# rows that change the object, not the camera: a random heading, or the held-out styles
OBJECTS = {"yaw unknown": {"yaw": True}, "cross-style (held-out styles)": {"split": "cross"}}


def run_row(name, objects, seed, checkpoint=None, dataset="procedural", root=None):
    """One row: every object once, from the same start and with the same draws as every row."""
    camera, believed_size, off = ROWS[name]
    split, yaw = OBJECTS.get(name, {}).get("split", "test"), OBJECTS.get(name, {}).get("yaw")
    sensor = sensor_config("realsense") if camera == "realsense" else sensor_config(**camera)
    k = sensor.intrinsics()
    test = open_dataset(dataset, root, split, cache_dir=default_cache_dir())
    rng = np.random.default_rng(seed)
    initial = LIMITS.initial_views(50)
    starts = initial[rng.integers(len(initial), size=len(test))]
    directions = rng.standard_normal((len(test), 3))
    directions /= np.linalg.norm(directions, axis=1, keepdims=True)
    yaws = rng.uniform(0, 2 * np.pi, len(test)) if yaw else np.zeros(len(test))
    core = ActiveRecognizer(checkpoint, EpisodeConfig(10, 0.1), seed=seed,
                            sensing=SensingConfig(object_size=believed_size), limits=LIMITS)
    hits3, hits_stop, views = [], [], []
    for i in objects:
        # metres: ModelNet's own (its files are in inches), else 1 m; kept within a household
        # object's, as a tenth of ModelNet10's test files are drawn in other units (a 115 m bathtub)
        size = shown_size(test, i)
        sim = SimulatedCamera(replace(sensor, object_size=size * sensor.object_size),
                              seed=seed * 100003 + int(i), offset=off * directions[i], yaw=yaws[i])
        sim.load(dataset=dataset, split=split, index=int(i), root=root or "")
        truth = test.classes[test.items[i][1]]
        core.reset(view=starts[i], sensing=SensingConfig(object_size=size * believed_size))
        labels = []
        while not core.done:
            pos, rot = core.requested_pose(k)
            shot = sim.capture(pos, rot)
            if shot is None:  # below the floor: no image, as when an arm cannot get there
                core.view_unreachable()
                continue
            metres, apos, arot = shot
            obs = core.observe(metres, k, apos, arot)
            if obs.status in ("classified", "recognized", "unsure"):
                labels.append(obs.label)
        labels = labels or [""]
        hits3.append(labels[min(3, len(labels)) - 1] == truth)
        hits_stop.append(labels[-1] == truth)
        views.append(len(labels))
    return name, hits3, hits_stop, views


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    add_flags(ap, EvalConfig, ["dataset", "root", "objects", "seed"], dataset={
        "choices": ("procedural", "modelnet"),
        "help": "whose test objects (modelnet: with --root; the cross-style row is procedural's own)"},
        objects={"default": OBJECTS_DEFAULT, "help": "test objects (seeded draw)"})
    ap.add_argument("--rows", nargs="*", default=None, help="rows to run (default: all)")
    ap.add_argument("--workers", type=int, default=2, help="processes (one row each at a time), >= 1")
    add_common_flags(ap, "checkpoint", "out", out="docs/results/camera_robustness.json, for modelnet "
                     "docs/results/modelnet10/camera_robustness.json")
    args = ap.parse_args(argv)
    with one_line_errors(ap):
        run(ap, args)


def run(ap, args):
    if args.workers < 1:
        ap.error(f"--workers must be at least 1, got {args.workers}")
    if (args.dataset == "modelnet") != bool(args.root):
        ap.error("--root goes with --dataset modelnet, and modelnet needs it")
    rows_here = [r for r in ROWS if args.dataset == "procedural" or "split" not in OBJECTS.get(r, {})]
    args.rows = rows_here if args.rows is None else args.rows
    unknown = sorted(set(args.rows) - set(rows_here))
    if unknown:
        ap.error(f"unknown rows {unknown}; choose from {rows_here}")
    partial = [flag for flag, on in (("--objects", args.objects != OBJECTS_DEFAULT), ("--seed", args.seed),
                                     ("--rows", args.rows != rows_here), ("--checkpoint", args.checkpoint)) if on]
    args.out = output(ap, args.out, str(results_dir(args.dataset) / "camera_robustness.json"), partial)
    args.checkpoint = str(checkpoint.model_path(args.checkpoint, args.dataset))
    checkpoint.load_model(args.checkpoint)  # a bad model file: refused here, not in every worker
    n_test = len(open_dataset(args.dataset, args.root, "test", cache_dir=default_cache_dir()))
    if not 1 <= args.objects <= n_test:
        ap.error(f"--objects must be 1..{n_test}")
    objects = np.sort(np.random.default_rng(args.seed).permutation(n_test)[:args.objects])
    rows = {}
    # spawned, not forked: a worker forked while one of this process's threads held a lock
    # (5 threads by then) waited on it for ever, every row unstarted after 10 minutes
    with ProcessPoolExecutor(args.workers, mp_context=multiprocessing.get_context("spawn")) as pool:
        jobs = [pool.submit(run_row, name, objects, args.seed, args.checkpoint, args.dataset,
                            args.root) for name in args.rows]
        for job in tqdm(jobs, desc="rows"):
            name, hits3, hits_stop, views = job.result()
            rows[name] = {"acc_3": float(np.mean(hits3)), "acc_stop": float(np.mean(hits_stop)),
                          "mean_views": float(np.mean(views)),
                          "stderr_3": float(np.std(hits3) / np.sqrt(len(hits3)))}
    for name, r in rows.items():
        print(f"{name:<32} acc@3 {r['acc_3']:.3f}  acc@stop {r['acc_stop']:.3f}  "
              f"views {r['mean_views']:.2f}")
    result = {"clean": rows.get("clean", {}).get("acc_3"),
              "realsense": rows.get("realsense", {}).get("acc_3"), "rows": rows,
              "objects": len(objects), "dataset": args.dataset,
              "checkpoint": args.checkpoint}
    if args.out:
        Path(args.out).parent.mkdir(parents=True, exist_ok=True)
        write_json(Path(args.out), result)
        if committed(args.out):
            write_results_page(RESULTS.parent / "RESULTS.md", RESULTS)
    print(json.dumps(result))


if __name__ == "__main__":
    main()
