# Copyright 2026 active_recognition maintainers
#
# Licensed under the Apache License, Version 2.0 (the "License");
# you may not use this file except in compliance with the License.
# You may obtain a copy of the License at
#
#     http://www.apache.org/licenses/LICENSE-2.0
#
# Unless required by applicable law or agreed to in writing, software
# distributed under the License is distributed on an "AS IS" BASIS,
# WITHOUT WARRANTIES OR CONDITIONS OF ANY KIND, either express or implied.
# See the License for the specific language governing permissions and
# limitations under the License.

"""The `active-recognition` command: one entry point, a subcommand per job."""
from __future__ import annotations

import argparse
import math
import sys
import warnings
from pathlib import Path

from .schedule import SCHEDULES
from .validation import Check, InputError, SEED_MAX, arg, arg_of, output_dir, output_file

SEED = arg(Check(int, lo=0, hi=SEED_MAX))


def cmd_render(args):
    from .visualize import render_mesh

    output_file(args.out, "--out", ".png")
    fov = None if args.fov is None else math.radians(args.fov)
    n, hit = render_mesh(args.mesh, args.out, args.views, args.theta, args.phi, args.size,
                         args.radius, fov)
    print(f"wrote {args.out}: {n} view(s) {args.size}x{args.size}, "
          f"{100 * hit:.1f}% of pixels hit the mesh")


def add_render(sub):
    p = sub.add_parser("render", help="render depth images of a mesh file to a PNG")
    p.add_argument("--mesh", required=True, help="mesh file (.off .obj .ply .stl .glb)")
    angle = arg(Check(float))
    p.add_argument("--theta", type=angle, default=math.radians(60), help="polar angle, radians")
    p.add_argument("--phi", type=angle, default=math.radians(30), help="azimuth, radians")
    p.add_argument("--views", type=arg(Check(int, lo=0, hi=100)), default=0,
                   help="render this many evenly spread views instead of one")
    p.add_argument("--size", type=arg(Check(int, lo=1, hi=1024)), default=64,
                   help="image height and width in pixels")
    p.add_argument("--radius", type=arg(Check(float, lo=0, lo_open=True, hi=100)), default=1.0,
                   help="viewing-sphere radius R")
    p.add_argument("--fov", type=arg(Check(float, lo=0, hi=180, lo_open=True, hi_open=True)),
                   default=None,
                   help="field of view in degrees (default: holds the [-0.5, 0.5]^3 cube)")
    p.add_argument("--out", default="depth.png", help="output PNG")
    p.set_defaults(func=cmd_render)


def cmd_dataset(args):
    from .datasets import GENERATED, default_cache_dir, describe

    if args.contact_sheet is not None:
        output_file(args.contact_sheet, "--contact-sheet", ".png")
    if args.sheet_split == "cross" and args.name not in GENERATED:  # refused before the indexing
        raise InputError(f"--sheet-split cross: the held-out styles are a generated benchmark's "
                         f"({', '.join(GENERATED)}); {args.name} has test")
    cache = None if args.no_cache else output_dir(
        default_cache_dir() if args.cache_dir is None else args.cache_dir,
        "--cache-dir" if args.cache_dir is not None else "cache folder (ACTIVE_RECOGNITION_CACHE)")
    splits = describe(args.name, args.root, cache)
    if args.contact_sheet:
        from .visualize import contact_sheet
        contact_sheet(args.name, args.root, splits, args.contact_sheet, args.sheet_split,
                      args.objects_per_class, args.views_per_object, args.seed)
        print(f"wrote {args.contact_sheet}")


def add_dataset(sub):
    from .datasets import NAMES
    p = sub.add_parser("dataset", help="index a dataset: class counts, skipped files, contact sheet")
    p.add_argument("--name", choices=NAMES, default="procedural", help="dataset layout")
    p.add_argument("--root", default=None, help="dataset root folder (not for procedural)")
    cache = p.add_mutually_exclusive_group()
    cache.add_argument("--cache-dir", default=None,
                       help="where parsed meshes are cached (default ~/.cache/active_recognition)")
    cache.add_argument("--no-cache", action="store_true", help="do not read or write the cache")
    p.add_argument("--contact-sheet", default=None, help="write a PNG grid of test-split depth images")
    p.add_argument("--sheet-split", default="test", choices=("test", "cross"),
                   help="the split on the sheet (cross: a generated benchmark's held-out styles)")
    p.add_argument("--objects-per-class", type=arg(Check(int, lo=1, hi=20)), default=2,
                   help="objects per class on the sheet")
    p.add_argument("--views-per-object", type=arg(Check(int, lo=1, hi=5)), default=3,
                   help="views per object on the sheet (front, side, top, below, three-quarter)")
    p.add_argument("--seed", type=SEED, default=0, help="which objects go on the sheet")
    p.set_defaults(func=cmd_dataset)


def cmd_train(args):
    import dataclasses

    from .devices import distributed, finish_distributed
    from .train import TrainConfig, preset_config, train

    flags = {f.name: getattr(args, f.name, None) for f in dataclasses.fields(TrainConfig)}
    model = {k: getattr(args, k) for k in ("hidden_size", "encoder", "max_step", "radius",
                                           "view_input", "candidates", "memory", "readout", "loc_hidden", "loc_step")}
    cfg = preset_config(args.config, flags, model)
    train(cfg)
    if distributed(cfg.device)[0] == 0:  # under torchrun, once
        print(f"checkpoints in {cfg.out}: {', '.join(written_checkpoints(cfg.out))}")
    finish_distributed()


def written_checkpoints(out):
    from pathlib import Path
    notes = {"pretrained.pt": " (after pre-training: --stage joint starts from it)", "last.pt": " (resumable)",
             "final.pt": ""}
    return [f"{name}{note}" for name, note in notes.items() if (Path(out) / name).exists()]


def add_train(sub):
    from .datasets import NAMES
    from .model import READOUTS, ModelConfig
    from .train import TrainConfig

    def own(name):
        return arg_of(TrainConfig, name)
    p = sub.add_parser("train", help="pre-train the classifier and train the model end to end")
    p.add_argument("--config", help="YAML preset of these options (flags override it)")
    p.add_argument("--dataset", choices=NAMES, help="dataset layout (default procedural)")
    p.add_argument("--root", type=own("root"), help="dataset root folder")
    p.add_argument("--out", type=own("out"), help="run folder for checkpoints and metrics.csv")
    p.add_argument("--stage", choices=("pretrain", "joint", "loc", "all"),
                   help="which stage(s) to run (default all; loc goes with --resume on a run whose joint "
                        "stage is done)")
    p.add_argument("--policy", choices=("learned", "reinforce", "hybrid", "imitation"),
                   help="how the view head learns: end to end through the depth layer (learned), "
                        "REINFORCE, both at once (hybrid), or FC_view imitating a label-aware teacher "
                        "(imitation, needs --candidates)")
    p.add_argument("--revisit-penalty", dest="revisit_penalty", type=own("revisit_penalty"),
                   help="learned: weight of the penalty on views within 30 degrees of earlier ones (0)")
    p.add_argument("--random-views", dest="random_views", type=own("random_views"),
                   help="learned, imitation: chance that a training step looks somewhere random "
                        "(imitation: an unvisited candidate), so the classifier learns from any "
                        "sequence of views (0)")
    p.add_argument("--distill-loc", dest="distill_loc", type=own("distill_loc"),
                   help="imitation: weight of FC_loc's loss toward the teacher's view, so the "
                        "paper's continuous head learns where the teacher looks (0)")
    p.add_argument("--imitation-mix", dest="imitation_mix", type=own("imitation_mix"),
                   help="imitation: chance that a training step follows the teacher (0.5)")
    p.add_argument("--pretrain-epochs", dest="pretrain_epochs", type=own("pretrain_epochs"),
                   help="stage 1 epochs")
    p.add_argument("--joint-epochs", dest="joint_epochs", type=own("joint_epochs"),
                   help="stage 2 epochs")
    p.add_argument("--loc-epochs", dest="loc_epochs", type=own("loc_epochs"),
                   help="stage loc (imitation, needs --loc-hidden): rounds in which FC_loc, the paper's "
                        "head, learns to move toward FC_view's choice, on episodes whose steps follow "
                        "FC_loc or, at --imitation-mix's chance, FC_view (0: no stage loc)")
    p.add_argument("--loc-hidden", dest="loc_hidden", type=arg_of(ModelConfig, "loc_hidden"),
                   help="width of FC_loc's hidden layer, beside the paper's single layer (0: none)")
    p.add_argument("--loc-step", dest="loc_step", type=arg_of(ModelConfig, "loc_step"),
                   help="with --loc-hidden: from stage loc on a step reaches max_step + this (rad; 0.8)")
    p.add_argument("--lr-loc", dest="lr_loc", type=own("lr_loc"), help="stage loc's learning rate (3e-4)")
    p.add_argument("--loc-passes", dest="loc_passes", type=own("loc_passes"),
                   help="stage loc: passes through each round's moves (100)")
    p.add_argument("--batch-size", dest="batch_size", type=own("batch_size"),
                   help="shapes per batch")
    p.add_argument("--steps", type=own("steps"), help="views per training episode (default 10)")
    p.add_argument("--views-per-shape", dest="views_per_shape", type=own("views_per_shape"),
                   help="pre-training images per shape per batch (default 4)")
    p.add_argument("--lr-pretrain", dest="lr_pretrain", type=own("lr_pretrain"),
                   help="stage 1 learning rate")
    p.add_argument("--lr-joint", dest="lr_joint", type=own("lr_joint"),
                   help="stage 2 learning rate")
    p.add_argument("--lr-schedule", dest="lr_schedule", choices=SCHEDULES,
                   help="each stage's learning rate: constant (default) or cosine down to 1 %%")
    p.add_argument("--lr-view-scale", dest="lr_view_scale", type=own("lr_view_scale"),
                   help="FC_loc's learning rate relative to the rest in the joint stage (1)")
    p.add_argument("--step-weighting", dest="step_weighting", choices=("uniform", "early"),
                   help="joint loss over the steps: uniform (the paper) or early (1/t)")
    p.add_argument("--initial-step", dest="initial_step", type=arg(Check(float)), nargs=2,
                   metavar=("DTHETA", "DPHI"),
                   help="radians: the view head's increment when the joint stage starts (0 0)")
    p.add_argument("--view-gradient", dest="view_gradient", choices=("paper", "surface"),
                   help="depth-layer backward rule")
    p.add_argument("--gradient-reduction", dest="gradient_reduction", choices=("mean", "sum"),
                   help="how per-pixel view gradients are reduced")
    p.add_argument("--eval-shapes", dest="eval_shapes", type=own("eval_shapes"),
                   help="validation shapes scored per epoch (metrics.csv)")
    p.add_argument("--checkpoint-every", dest="checkpoint_every", type=own("checkpoint_every"),
                   help="write last.pt every N batches")
    p.add_argument("--max-shapes", dest="max_shapes", type=own("max_shapes"),
                   help="train on a seeded subset")
    p.add_argument("--mirror", type=own("mirror"),
                   help="augment: the chance a training object is mirrored left to right (0)")
    p.add_argument("--stretch", type=own("stretch"),
                   help="augment: each axis of a training object scaled by a factor within "
                        "[1/(1+S), 1+S], log-uniform (0)")
    p.add_argument("--yaw-range", dest="yaw_range", type=own("yaw_range"),
                   help="degrees: --yaw turns objects within +-this (180, the whole turn)")
    p.add_argument("--yaw", action="store_true", default=None,
                   help="augment: turn every training object by a random yaw about z (for an "
                        "object frame of unknown heading)")
    p.add_argument("--frame-error", dest="frame_error", type=own("frame_error"),
                   help="augment: object frame off by up to this fraction of the object's size, in "
                        "centre and in size (a detector's error; 0.25 in the shipped preset)")
    p.add_argument("--floor-cut", dest="floor_cut", type=own("floor_cut"),
                   help="augment: cut away up to this fraction of the object's bottom (0)")
    p.add_argument("--dropout", type=own("dropout"),
                   help="augment: up to this fraction of each image's pixels, and as many of its "
                        "depth-edge pixels, missing (0)")
    p.add_argument("--steep-dropout", dest="steep_dropout", type=own("steep_dropout"),
                   help="augment: the chance that an image loses its pixels beside jumps steeper "
                        "than a surface seen 70-85 degrees from face-on, as a depth camera's "
                        "flying-pixel filter removes them (0)")
    p.add_argument("--min-elevation", dest="min_elevation", type=own("min_elevation"),
                   help="degrees: no training view from lower (-90: the whole sphere; 0: nothing "
                        "from below an object on a floor)")
    p.add_argument("--max-elevation", dest="max_elevation", type=own("max_elevation"),
                   help="degrees: no training view from higher (90)")
    p.add_argument("--seed", type=SEED, help="seed of every random choice")
    p.add_argument("--device", type=own("device"), help="cpu, cuda or cuda:N")
    p.add_argument("--resume", action="store_true", help="continue from OUT/last.pt")
    p.add_argument("--hidden-size", dest="hidden_size", type=arg_of(ModelConfig, "hidden_size"),
                   help="RNN hidden size (256)")
    p.add_argument("--encoder", choices=("compact", "wide", "alexnet"), help="Conv2D encoder")
    p.add_argument("--max-step", dest="max_step", type=arg_of(ModelConfig, "max_step"),
                   help="view increment bound, radians")
    p.add_argument("--radius", type=arg_of(ModelConfig, "radius"), help="viewing-sphere radius R")
    p.add_argument("--view-input", dest="view_input", action="store_true", default=None,
                   help="feed the current view to the RNN (MV-RNN style)")
    p.add_argument("--memory", choices=("rnn", "rnn+max"),
                   help="the state the heads read: the RNN's (the paper), or beside it the running "
                        "maximum of the image features seen (rnn+max)")
    p.add_argument("--readout", choices=READOUTS,
                   help="the answer after t views: FC_class on the last state (last, the paper), "
                        "the mean of every step's class probabilities (mean), or that mean with "
                        "each step's averaged with its mirror image's (mean+mirror)")
    p.add_argument("--candidates", type=arg_of(ModelConfig, "candidates"),
                   help="size of FC_view, the head scoring candidate views (imitation; 0 = none)")
    p.set_defaults(func=cmd_train)


def cmd_demo(args):
    import importlib.util
    if importlib.util.find_spec("rclpy") is None:
        raise InputError("the demo needs ROS 2's rclpy: install with pip install '.[ros]' "
                         "or source a ROS 2 install")
    from .nodes.demo import run_demo
    run_demo(objects=args.objects, seed=args.seed, checkpoint=args.checkpoint or "",
             planner=args.planner, dataset=args.dataset, camera=args.camera,
             record=args.record or "")


def add_demo(sub):
    p = sub.add_parser("demo", help="closed loop over ROS topics: recognizer + simulated camera")
    from .recognizer import NODE_PLANNERS
    p.add_argument("--objects", type=arg(Check(int, lo=1, hi=100_000)), default=10,
                   help="test objects to recognise")
    p.add_argument("--dataset", choices=("procedural", "twins"), default="procedural",
                   help="embedded dataset whose test objects the simulated camera shows")
    p.add_argument("--seed", type=SEED, default=0, help="which objects and initial views")
    p.add_argument("--checkpoint", default=None,
                   help="model file (default: the dataset's shipped model)")
    p.add_argument("--planner", choices=NODE_PLANNERS, default="auto",
                   help="next-view planner (auto: the model's best, as measured)")
    p.add_argument("--camera", choices=("virtual", "realsense"), default="virtual",
                   help="simulated camera: the model's own (64x64, 120 degrees), or "
                        "RealSense-like (640x480, fx = fy = 385, Kinect noise, 3 %% dropout, "
                        "flying pixels removed, a floor, 2 degrees of pose error)")
    p.add_argument("--record", metavar="FILE.mcap", default=None,
                   help="record every topic of the loop to this MCAP file (ros2 bag play, "
                        "Foxglove)")
    p.set_defaults(func=cmd_demo)


def cmd_evaluate(args):
    import json

    from .evaluate import EvalConfig, evaluate, planner_checkpoints, summary
    from .run_metrics import load_run_pair

    runs = load_run_pair(args.learned_metrics, args.reinforce_metrics)  # read before the work
    cfg = EvalConfig(checkpoint=args.checkpoint, reinforce_checkpoint=args.reinforce_checkpoint,
                     planner_checkpoints=planner_checkpoints(args.planner_checkpoint),
                     planners=tuple(p.strip() for p in args.planners.split(",")),
                     dataset=args.dataset, root=args.root, split=args.split, objects=args.objects,
                     starts=args.starts, steps=args.steps,
                     entropy_threshold=args.entropy_threshold, seed=args.seed, out=args.out,
                     shared=not args.no_shared, min_elevation=args.min_elevation,
                     max_elevation=args.max_elevation, readout=args.readout, yaw=args.yaw,
                     size=not args.no_size, judge=args.judge, keep_judge=args.judge is not None)
    s = summary(evaluate(cfg, runs=runs))
    if args.steps < 3:  # the tables are after 3, 6 and 9 views
        print(f"active-recognition evaluate: note: episodes of {args.steps} view(s) have no accuracy after 3, 6 or "
              f"9 views; the accuracy after each view is in {args.out}/accuracy_vs_views.png", file=sys.stderr)
    print(f"report: {args.out}/report.md")
    print(json.dumps(s["acc"]))


def add_evaluate(sub):
    from .datasets import NAMES
    from .evaluate import EvalConfig
    from .model import READOUTS
    from .policies import PLANNERS

    def own(name):
        return arg_of(EvalConfig, name)
    p = sub.add_parser("evaluate", help="compare view planners on a dataset split")
    p.add_argument("--checkpoint", default=None, help="learned model (default: the shipped one)")
    p.add_argument("--reinforce-checkpoint", default=None,
                   help="model trained with 'train --policy reinforce' (for the reinforce planner)")
    p.add_argument("--planner-checkpoint", action="append", default=[], metavar="PLANNER=FILE",
                   help="a planner's own model, e.g. learned=runs/e2e/final.pt (repeatable); "
                        "planners without one use --checkpoint")
    p.add_argument("--planners", default="learned,random,straight,oracle",
                   help=f"comma-separated, from {','.join(PLANNERS)}")
    p.add_argument("--dataset", choices=NAMES, default="procedural", help="dataset layout")
    p.add_argument("--root", default=None, help="dataset root folder")
    p.add_argument("--split", default="test", choices=("train", "val", "test", "cross"),
                   help="which split (val: a seeded tenth of each class of train, where choices "
                        "are made; cross: a generated benchmark's held-out styles)")
    p.add_argument("--objects", type=own("objects"), default=0,
                   help="seeded sample of objects (0: all)")
    p.add_argument("--starts", type=own("starts"), default=1,
                   help="initial views per object (of the 50)")
    p.add_argument("--steps", type=own("steps"), default=10, help="views per episode")
    p.add_argument("--entropy-threshold", type=own("entropy_threshold"), default=0.1,
                   help="early-stop entropy (nats)")
    p.add_argument("--seed", type=SEED, default=0, help="objects, initial views, random planner")
    p.add_argument("--out", default="runs/eval", help="report folder")
    p.add_argument("--no-shared", action="store_true", help="skip the shared multi-view classifier")
    p.add_argument("--judge", default=None,
                   help="a trained shared classifier to score with and pick the fixed path by, used as "
                        "it is (e.g. docs/results/modelnet10/shared_classifier.pt); refused if trained on "
                        "other shapes or through another camera (default: OUT/shared_classifier.pt, "
                        "trained there first, minutes)")
    p.add_argument("--min-elevation", type=own("min_elevation"), default=-90.0,
                   help="degrees: views from no lower; the initial views are the paper's 50 above it "
                        "(-90: the whole sphere, the paper's)")
    p.add_argument("--max-elevation", type=own("max_elevation"), default=90.0,
                   help="degrees: views from no higher")
    p.add_argument("--no-size", action="store_true",
                   help="answer from the images alone, though the model carries a size prior "
                        "(modelnet10.pt weighs each object's size, as the node's object_size)")
    p.add_argument("--readout", choices=READOUTS, default=None,
                   help="the answer after t views: the last step's (last), the mean of every "
                        "step's class probabilities (mean), or that mean with each step's "
                        "averaged with its mirror image's (mean+mirror); default each model's own")
    p.add_argument("--yaw", type=own("yaw"), default=0.0,
                   help="degrees: turn every object by its own seeded yaw within +-this (0)")
    p.add_argument("--learned-metrics", default=None, help="metrics.csv of the learned run")
    p.add_argument("--reinforce-metrics", default=None, help="metrics.csv of the reinforce run")
    p.set_defaults(func=cmd_evaluate)


class Parser(argparse.ArgumentParser):
    """argparse, but a bad option is one line (the error and where help is), not the usage."""

    def error(self, message):
        self.exit(2, f"{self.prog}: error: {message} (see {self.prog} --help)\n")


def build_parser():
    parser = Parser(prog="active-recognition", description=__doc__)
    sub = parser.add_subparsers(dest="command", required=True)
    for add in ADDERS:
        add(sub)
    return parser


ADDERS = [add_render, add_dataset, add_train, add_evaluate, add_demo]


def one_line_warning(message, category, filename, lineno, line=None, default=warnings.formatwarning):
    """This package's own warnings as one line, as its errors are; others as Python shows them."""
    if category is UserWarning and Path(__file__).parent in Path(filename).resolve().parents:
        return f"active-recognition: warning: {message}\n"
    return default(message, category, filename, lineno, line)


def main(argv=None):
    args = build_parser().parse_args(argv)
    previous, warnings.formatwarning = warnings.formatwarning, one_line_warning
    try:
        return args.func(args) or 0
    except (InputError, OSError) as e:  # bad options, files, checkpoints, meshes; paths
        print(f"active-recognition {args.command}: error: {e}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print(f"active-recognition {args.command}: interrupted", file=sys.stderr)
        return 130
    finally:
        warnings.formatwarning = previous


if __name__ == "__main__":
    sys.exit(main())
