# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""Planners compared on the same episodes of a dataset's test split: learned (end to end), random,
straight, reinforce, fixed (the best fixed path), imitation (FC_view imitating the oracle) and the
privileged oracle; each with its own recurrent classifier and with one shared multi-view
classifier, the standard error of every 3-view figure, and the wall-clock for `learned` to reach
the best accuracy `reinforce` reaches, over reinforce's time. The default planner (`--ship` records
it in the shipped model, for the recognizer's `auto`) is chosen on the validation split
(docs/results/<dataset>/val/), before the test split is read: there the fixed path is picked on
a seeded half of the objects and every planner is scored on the other half.
Writes the report under docs/results/ (docs/results/<dataset>/ for other datasets than
procedural, docs/results/<dataset>-cross/ for `--split cross`, the held-out styles) and
re-renders docs/RESULTS.md; a smaller or other run (--objects, --starts, --checkpoint,
--planner-checkpoint) must name its own --out and leaves RESULTS.md as it is. Last line is JSON."""
import argparse
from dataclasses import replace
from pathlib import Path

from common import FOLDER, RESULTS, committed, emit, one_line_errors, output, results_dir
from results_page import write_results_page
from robot_seconds import BUDGETS, robot_summary

from active_recognition.datasets import default_cache_dir, open_dataset
from active_recognition.evaluation.evaluate import EvalConfig, evaluate, halves, summary
from active_recognition.evaluation.report import PAPER_MODELNET10, write_json
from active_recognition.model import checkpoint
from active_recognition.model.checkpoint import MODELS, SHIPPED_FOR
from active_recognition.model.policies import FIXED
from active_recognition.options.flags_and_parameters import add_flags
from active_recognition.sensing.reach import ViewLimits
from active_recognition.training.run_metrics import read_metrics, training_time

ROOT = Path(__file__).resolve().parents[1]
# the planners each dataset's shipped models serve, and the model file of each: the shipped
# model (checkpoint.SHIPPED_FOR), its REINFORCE twin beside it
EVERY = ("learned", "random", "straight", "reinforce", "fixed", "imitation", "oracle")
PLANNERS = {"procedural": EVERY[:-1] + ("fixed+imitation", "oracle"),
            "twins": EVERY, "modelnet": EVERY[:-1] + ("fixed+imitation", "oracle")}
CHECKPOINTS = {d: {"learned": f, "reinforce": f.replace(".pt", "_reinforce.pt"), "imitation": f}
               for d, f in SHIPPED_FOR.items()}


def refuse_unrecorded_default(ap, args, model):
    """--ship on a ModelNet10 model that records no default planner ends here: the node's model
    has its default chosen through a camera on val (validation_camera.py --ship), which the
    renders' rule here must not overwrite (a fresh train or open_set_fit output records none)."""
    if args.ship and args.dataset == "modelnet" and not checkpoint.read(model).get("default_planner"):
        ap.error(f"{model} records no default planner: ModelNet10's is chosen through the camera on "
                 f"val; record it first (python benchmarks/validation_camera.py --root DIR --ship), "
                 f"then --ship here")


def ship(path, s):
    """Record in a shipped model the planner 'auto' stands for, and the fixed path."""
    checkpoint.update(path, default_planner=s["default_planner"],
                      **({"fixed_path": s["fixed_path"]} if "fixed_path" in s else {}))
    print(f"{path}: default planner {s['default_planner']}")


def choose_default(cfg: EvalConfig, out):
    """The default planner: the best of the planners a robot can use (not the oracle) after 3
    views with the model's own classifier, on the validation split (a tie goes to the better
    after 6 views, then 9); with cfg.objects, on as many validation objects, where it holds them.
    -> (name, {planner: acc after 3 views})."""
    fair = [p for p in cfg.planners if p != "oracle"]
    judge = Path(out) / "shared_classifier.pt"  # the fixed path's judge, the test run's too
    objects = 0
    if cfg.objects:  # the fixed path is picked on one half of val, every planner scored on the other
        total = len(open_dataset(cfg.dataset, cfg.root, "val", cache_dir=default_cache_dir()))
        objects = min(cfg.objects, len(halves(total, cfg.seed)[1]) if set(fair) & set(FIXED) else total)
    s = summary(evaluate(replace(cfg, split="val", objects=objects, planners=tuple(fair), shared=False,
                                 out=str(Path(out) / "val"), judge=str(judge))))
    acc = {k: v["3"] for k, v in s["acc"].items()}
    # a tie after 3 views (fixed and fixed+imitation share their first 3) goes to the better after 6, then 9
    return max(acc, key=lambda k: (acc[k], s["acc"][k]["6"], s["acc"][k]["9"])), acc


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawTextHelpFormatter)
    add_flags(ap, EvalConfig, ["dataset", "root", "checkpoint"], dataset={"choices": sorted(PLANNERS)},
              checkpoint={"help": "the model that scores random, straight, fixed and oracle views "
                                  "(default: the dataset's shipped model)"})
    ap.add_argument("--planner-checkpoint", action="append", default=[], metavar="PLANNER=FILE",
                    help="a planner's own model (default: the shipped ones)")
    ap.add_argument("--learned-metrics", default=None, help="metrics.csv of the learned run")
    ap.add_argument("--reinforce-metrics", default=None, help="metrics.csv of the reinforce run")
    add_flags(ap, EvalConfig, ["split", "objects", "starts"], split={
        "choices": ("test", "cross"), "help": "test, or cross: the held-out styles (a proxy for real objects)"},
        objects={"help": "0: the whole test split; else a seeded sample of this many test objects, and as "
                         "many validation objects for the default (a partial run: give --out)"},
        starts={"default": 3})
    # --out by hand: a folder, not a JSON file
    ap.add_argument("--out", default=None, help="report folder (default docs/results[/DATASET])")
    yaw = ("degrees: every object turned by its own seeded yaw within +-this (a detector's rough heading); "
           "results go to docs/results/<dataset>-yaw<N>")
    size = "answer from the images alone, though the model carries a size prior (default out: the dataset's " \
           "folder/images_only)"
    add_flags(ap, EvalConfig, ["min_elevation", "max_elevation", "yaw", "size"], yaw={"help": yaw},
              size={"help": size})
    ap.add_argument("--ship", action="store_true",
                    help="write the measured best planner (and the fixed path) into the "
                         "dataset's shipped model, for the recognizer's planner 'auto'")
    args = ap.parse_args()
    with one_line_errors(ap):
        run(ap, args)


def run(ap, args):
    if args.ship and args.split != "test":
        ap.error("--ship records the default planner for the test split's models; leave out --split")
    if args.ship and not args.size:
        ap.error("--ship records the default planner of the model as the node runs it; leave out --no-size")
    if args.ship and args.yaw:
        ap.error("--ship records the default planner chosen at the canonical heading; leave out --yaw")
    if (args.dataset == "modelnet") != bool(args.root):
        ap.error("--root goes with --dataset modelnet, and modelnet needs it (README: ModelNet10)")
    if args.split == "cross" and args.dataset == "modelnet":
        ap.error("the cross split is a generated benchmark's; ModelNet10 has test")
    runs = results_dir(args.dataset)
    cross = RESULTS / f"{args.dataset}-cross"  # the held-out styles
    turned = RESULTS / f"{FOLDER[args.dataset] or args.dataset}-yaw{args.yaw:g}"
    partial = [flag for flag, on in (("--objects", args.objects), ("--starts", args.starts != 3),
                                     ("--checkpoint", args.checkpoint),
                                     ("--planner-checkpoint", args.planner_checkpoint)) if on]
    if args.ship and partial:
        ap.error(f"--ship records what the whole benchmark chose; leave out {', '.join(partial)}")
    out = Path(output(ap, args.out, cross if args.split == "cross" else turned if args.yaw else
                      runs if args.size else runs / "images_only", partial))
    own = {name: str(MODELS / f) for name, f in CHECKPOINTS[args.dataset].items()}
    for item in args.planner_checkpoint:
        name, sep, path = item.partition("=")
        if not sep:
            ap.error(f"--planner-checkpoint {item!r}: expected PLANNER=FILE")
        own[name] = path
    model = str(checkpoint.model_path(args.checkpoint, args.dataset))
    for path in {model, *own.values()}:
        if not Path(path).is_file():
            ap.error(f"{path}: no such model (train it with its config/train_*.yaml, or pass "
                     f"--checkpoint / --planner-checkpoint)")
        checkpoint.load_model(path)  # a file that is not a model: refused now, not after the validation run
    refuse_unrecorded_default(ap, args, model)
    metrics = {k: getattr(args, f"{k}_metrics") or str(runs / f"{k}_metrics.csv")
               for k in ("learned", "reinforce")}
    for path in metrics.values():
        if not Path(path).is_file():
            ap.error(f"{path}: no such metrics file (train the run first, or pass --*-metrics)")
    held = len(open_dataset(args.dataset, args.root, args.split, cache_dir=default_cache_dir()))
    if not 0 <= args.objects <= held:  # refused now, not after the validation run
        ap.error(f"--objects must be 0 (all) .. {held}, the {args.split} split's objects")
    cfg = EvalConfig(checkpoint=model, planner_checkpoints=own, planners=PLANNERS[args.dataset],
                     dataset=args.dataset, root=args.root, split=args.split, objects=args.objects,
                     starts=args.starts, out=str(out), yaw=args.yaw, size=args.size,
                     limits=ViewLimits(args.min_elevation, args.max_elevation))
    chosen_by = None
    if args.split == "test":  # on the validation split, before test is read
        chosen, val_acc = choose_default(cfg, out)
        if args.dataset == "modelnet":  # the node's model, for a robot's camera: its default is chosen
            # through one on val (validation_camera.py --ship); the renders' scores stay in val_acc_3
            recorded = checkpoint.read(model).get("default_planner")
            if recorded:
                chosen, chosen_by = recorded, "validation_camera.json"
    else:  # the held-out styles: the default the test run chose, as the shipped model records it
        chosen, val_acc = checkpoint.read(model).get("default_planner"), None
    results = evaluate(cfg)
    s = summary(results)
    t = training_time(read_metrics(metrics["learned"]), read_metrics(metrics["reinforce"]),
                      out / "training_time.png")
    s["training_time"] = t
    s["default_planner"], s["val_acc_3"] = chosen, val_acc
    s["robot_seconds"] = robot_summary(out / "per_object.csv")  # what the episodes cost an arm
    if chosen_by:
        s["default_chosen_by"] = chosen_by
    if args.dataset == "modelnet":  # the paper's Table 3, accuracy % after 3 / 6 / 9 views
        s["paper"] = {k: list(v) for k, v in PAPER_MODELNET10.items()}
    write_json(out / "summary.json", s)
    if args.ship:
        ship(checkpoint.shipped(args.dataset), s)
    if committed(out):  # a run elsewhere leaves the committed page as it is
        write_results_page(ROOT / "docs/RESULTS.md", RESULTS)
    for name in s["acc"]:
        print(f"{name:>10}: 3 views {100 * s['acc'][name]['3']:.1f} +- {100 * s['stderr_3'][name]:.1f}"
              f", shared classifier {100 * s['acc_shared'][name]['3']:.1f} +- "
              f"{100 * s['stderr_3_shared'][name]:.1f}")
    for name, f in s["robot_seconds"].items():
        print(f"{name:>10}: travel after 3 / 6 / 9 views {f['travel_deg_3']:.0f} / {f['travel_deg_6']:.0f} / "
              f"{f['travel_deg_9']:.0f} deg; stop rule {f['stop_seconds_mean']:.1f} / {f['stop_seconds_p90']:.1f} "
              f"robot s (mean / p90); within " + ", ".join(f"{b:g} s {100 * f[f'budget_{b:g}_accuracy']:.1f}"
                                                           for b in BUDGETS) + " %")
    line = {"acc": s["acc"], "shared_acc": s["acc_shared"], "stderr_3": s["stderr_3"],
            "default_planner": s["default_planner"], "learned_vs_reinforce_time_ratio": t["ratio"]}
    if "paper" in s:
        line["paper"] = s["paper"]
    emit(line)


if __name__ == "__main__":
    main()
