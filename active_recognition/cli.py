# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""The `active-recognition` command: a subcommand per job, its flags made from its options."""
from __future__ import annotations

import math
import sys
import warnings
from pathlib import Path

from active_recognition.argument_checks import InputError, group, output_dir, output_file
from active_recognition.evaluation.evaluate import EvalConfig
from active_recognition.options import command_options as co
from active_recognition.options.flags_and_parameters import Parser, add_flags
from active_recognition.training.train_config import TrainConfig
from active_recognition.unknown.fit import add_fit_flags


def cmd_render(args):
    from active_recognition.training.visualize import render_mesh

    output_file(args.out, "--out", ".png")
    fov = None if args.fov is None else math.radians(args.fov)
    n, hit = render_mesh(args.mesh, args.out, args.views, args.theta, args.phi, args.size,
                         args.radius, fov)
    print(f"wrote {args.out}: {n} view(s) {args.size}x{args.size}, "
          f"{100 * hit:.1f}% of pixels hit the mesh")


def cmd_dataset(args):
    from active_recognition.datasets import GENERATED, default_cache_dir, describe

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
        from active_recognition.training.visualize import contact_sheet
        contact_sheet(args.name, args.root, splits, args.contact_sheet, args.sheet_split,
                      args.objects_per_class, args.views_per_object, args.seed)
        print(f"wrote {args.contact_sheet}")


def cmd_train(args):
    from active_recognition.training.devices import distributed, finish_distributed
    from active_recognition.training.train import preset_config, train

    cfg = preset_config(args.config, vars(args))
    train(cfg)
    notes = {"pretrained.pt": " (after pre-training: --stage joint starts from it)", "last.pt": " (resumable)",
             "final.pt": ""}
    if distributed(cfg.device)[0] == 0:  # under torchrun, once
        print(f"checkpoints in {cfg.out}: "
              f"{', '.join(n + note for n, note in notes.items() if (Path(cfg.out) / n).exists())}")
    finish_distributed()


def need_rclpy(what):
    import importlib.util
    if importlib.util.find_spec("rclpy") is None:
        raise InputError(f"{what} needs ROS 2's rclpy: install with pip install '.[ros]' "
                         "or source a ROS 2 install")


def cmd_demo(args):
    need_rclpy("the demo")
    from active_recognition.nodes.demo import run_demo
    run_demo(objects=args.objects, seed=args.seed, checkpoint=args.checkpoint or "",
             planner=args.planner, dataset=args.dataset, camera=args.camera,
             record=args.record or "", time_budget=args.time_budget)


def cmd_recognize(args):
    need_rclpy("recognize")
    from active_recognition.nodes.recognize_client import run_goal
    from action_msgs.msg import GoalStatus

    result, state = run_goal(args.action, args.object_frame, args.object_size, args.max_views, args.timeout,
                             time_budget=args.time_budget)
    if state == GoalStatus.STATUS_CANCELED:  # by Ctrl-C; a goal another start replaced is aborted
        return 130
    return 0 if result is not None and result.status in ("recognized", "unknown") else 1


def cmd_evaluate(args):
    import json

    from active_recognition.evaluation.evaluate import EvalConfig, evaluate, planner_checkpoints, summary
    from active_recognition.training.run_metrics import load_run_pair

    runs = load_run_pair(args.learned_metrics, args.reinforce_metrics)  # read before the work
    cfg = EvalConfig(**group(EvalConfig, vars(args)), keep_judge=args.judge is not None,
                     planner_checkpoints=planner_checkpoints(args.planner_checkpoint))
    s = summary(evaluate(cfg, runs=runs))
    if args.steps < 3:  # the tables are after 3, 6 and 9 views
        print(f"active-recognition evaluate: note: episodes of {args.steps} view(s) have no accuracy after 3, 6 or "
              f"9 views; the accuracy after each view is in {args.out}/accuracy_vs_views.png", file=sys.stderr)
    print(f"report: {args.out}/report.md")
    print(json.dumps(s["acc"]))


def cmd_open_set_fit(args):
    from active_recognition.unknown.fit import run
    run(args)


def add_commands(sub):
    """Each subcommand's parser: its flags generated from its options' dataclass (options/flags_and_parameters.py)."""
    add_flags(sub.add_parser("render", help="render depth images of a mesh file to a PNG"),
              co.RenderOptions).set_defaults(func=cmd_render)
    add_flags(sub.add_parser("dataset", help="index a dataset: class counts, skipped files, contact sheet"),
              co.DatasetOptions).set_defaults(func=cmd_dataset)
    p = sub.add_parser("train", help="pre-train the classifier and train the model end to end")
    p.add_argument("--config", help="YAML preset of these options (flags override it)")
    add_flags(p, TrainConfig, unset=True).set_defaults(func=cmd_train)
    p = sub.add_parser("evaluate", help="compare view planners on a dataset split")
    add_flags(p, EvalConfig).set_defaults(func=cmd_evaluate)
    p.add_argument("--planner-checkpoint", action="append", default=[], metavar="PLANNER=FILE",
                   help="a planner's own model, e.g. learned=runs/e2e/final.pt (repeatable); "
                        "planners without one use --checkpoint")
    add_flags(p, co.EvaluateRuns)
    add_flags(sub.add_parser("demo", help="closed loop over ROS topics: recognizer + simulated camera"),
              co.DemoOptions).set_defaults(func=cmd_demo)
    add_flags(sub.add_parser("recognize", help=(
        "send one goal to a running recognizer: feedback per image, the result; Ctrl-C cancels")),
        co.RecognizeOptions).set_defaults(func=cmd_recognize)
    add_fit_flags(sub.add_parser("open-set-fit", help=(
        "fit a model's unknown answer (class means, a threshold per view) on validation and store it "
        "in its checkpoint"))).set_defaults(func=cmd_open_set_fit)


def build_parser():
    parser = Parser(prog="active-recognition", description=__doc__.split("\n\n")[0])
    add_commands(parser.add_subparsers(dest="command", required=True))
    return parser


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
