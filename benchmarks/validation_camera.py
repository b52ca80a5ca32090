# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""The node's planners and `unknown` scores on ModelNet10's validation split as the node meets
it: every val object shot through a simulated camera and the recognizer's own path
(SimulatedCamera -> ActiveRecognizer.observe; camera_episodes.py), `--starts` seeded starts each
(the same for every planner), 10 views without a stop or a hold; the real unknowns' val split
(datasets/real_unknowns.py, under --unknowns-root), or with `--unknowns unknowns` the generated
unknowns' val styles (datasets/unknowns.py), beside them; the AUROCs compare both groups' first
start. Test objects are never read.

Prints, per planner, the accuracy after 3, 6 and 9 views (the closed-set answer) and its mean,
the paired difference of that mean from the checkpoint's default planner (or --reference's),
which runs beside them (the committed run's was learned), with its standard error, and the AUROC of prototype_mean,
energy_mean and msp_mean after 1, 3, 6 and 10 views.
`rule` names the default the validation split supports: of the planners whose mean is within
one paired standard error of the best's, the one whose running score of the node's `unknown`
answer (the checkpoint's open_set score: prototype_mean, or energy_mean) tells the val unknowns
best after 10 views. (Stated before the first run, 2026-12-02:
the default, learned, stays unless the best leads it by more than one paired standard error;
the tie-break by AUROC was added after learned and imitation tied on accuracy.) Writes
docs/results/modelnet10/validation_camera.json (a partial run must give --out); last line JSON.
With --ship the chosen planner becomes modelnet10.pt's `default_planner` (the node's planner
`auto`) and docs/results/modelnet10/summary.json's: ModelNet10's model serves a robot's camera,
so its default is chosen here, and benchmarks/planners.py keeps it. The `unknown` thresholds are
fitted for the planner `auto` names: after a change, fit them again (active-recognition
open-set-fit --camera realsense).

`--scores CSV` also writes the default planner's episodes of the first start, known and unknown,
one row each: its group, object, class and `near`, and per view the answer, the prototype score,
the energy and 1 - the top probability (for choosing another score without shooting them again).

    python benchmarks/validation_camera.py --root ~/data/ModelNet10 --unknowns-root ~/data/real_unknowns
        [--starts 3] [--objects 0] [--ship]
"""
import argparse
import csv
import json
from pathlib import Path

import numpy as np
from common import add_common_flags, add_unknowns_flags, emit, one_line_errors, output, results_dir

from active_recognition.atomic_files import atomic_write
from active_recognition.datasets import default_cache_dir, open_dataset, open_splits
from active_recognition.datasets.real_unknowns import near as is_near
from active_recognition.evaluation.camera_episodes import camera_runs, recording_core
from active_recognition.evaluation.report import write_json
from active_recognition.model import checkpoint
from active_recognition.runtime.active_recognizer import NODE_PLANNERS
from active_recognition.unknown import scores as open_set

STEPS = 10
CUTS = (3, 6, 9)  # views after which the closed-set answer is scored
AUROC_AT = (1, 3, 6, 10)
PLANNERS = ("learned", "imitation", "random")
CHOICES = tuple(p for p in NODE_PLANNERS if p != "auto")  # auto is the default, run anyway
STARTS, SEED = 3, 1000


def answers(runs, steps=STEPS):
    """(N, steps) the class each run answered after 1..steps images (-1 before its first)."""
    out = np.full((len(runs), steps), -1)
    for j, run in enumerate(runs):
        classes = [int(np.argmax(p)) for p in run.probs[:steps]]
        if classes:
            out[j, :len(classes)] = classes
            out[j, len(classes):] = classes[-1]
    return out


def running_end(values, t):
    """The mean of a run's first t per-view scores (inf where it scored none: unknown-looking)."""
    return float(np.mean(values[:t])) if len(values[:t]) else float("inf")


def end_scores(runs, t):
    """{score: (N,)} of runs after t views: the running means the recognizer keeps."""
    return {"prototype_mean": np.array([running_end(r.prototypes, t) for r in runs]),
            "energy_mean": np.array([running_end(r.energies, t) for r in runs]),
            "msp_mean": np.array([running_end(open_set.msp(r.probs) if r.probs else [], t) for r in runs])}


def planner_runs(path, planner, groups, preset, starts, seed):
    """{known: [runs of each start], unknown: runs} of one planner (a core of its own, seeded 0);
    groups: ((dataset, name, root, count), (dataset, name, root, count))."""
    core = recording_core(path, planner, STEPS)
    (known, kname, root, nk), (unknown, uname, uroot, nu) = groups
    runs = {"known": [camera_runs(core, known, kname, "val", np.arange(nk), preset, seed + s, root, record=True)
                      for s in range(starts)]}
    runs["unknown"] = camera_runs(core, unknown, uname, "val", np.arange(nu), preset, seed, uroot, record=True)
    return runs


def summarise(runs, near=None):
    """One planner's accuracies, per-episode right (episodes, cuts) and AUROCs (and, given the
    unknowns' `near` mask, the AUROCs of the near ones alone)."""
    right = np.concatenate([answers(r)[:, [c - 1 for c in CUTS]] == np.array([x.label for x in r])[:, None]
                            for r in runs["known"]])
    first, unknown = runs["known"][0], runs["unknown"]
    auroc, auroc_near = {}, {}
    for t in AUROC_AT:
        k, u = end_scores(first, t), end_scores(unknown, t)
        for name in [n for n in k if np.isfinite(k[n]).any() or np.isfinite(u[n]).any()]:  # scored
            # (prototype_mean needs the class means of a checkpoint's open_set)
            auroc.setdefault(name, []).append(round(open_set.auroc(k[name], u[name]), 4))
            if near is not None and near.any():
                auroc_near.setdefault(name, []).append(round(open_set.auroc(k[name], u[name][near]), 4))
    return right, {"acc": {str(c): round(float(right[:, i].mean()), 4) for i, c in enumerate(CUTS)},
                   "mean": round(float(right.mean()), 4), "episodes": len(right), "auroc": auroc,
                   **({"auroc_near": auroc_near} if auroc_near else {})}


def paired(right, a, b):
    """(mean, standard error) of the per-episode difference a - b of the 3/6/9-view mean."""
    diff = right[a].mean(1) - right[b].mean(1)
    return float(diff.mean()), float(diff.std(ddof=1) / np.sqrt(len(diff))) if len(diff) > 1 else float("inf")


def score_rows(runs, near=None):
    """The --scores CSV's rows of a planner's first start, known and unknown (see the module)."""
    per_view = [f"{k}_{t}" for k in ("answer", "prototype", "energy", "msp") for t in range(1, STEPS + 1)]
    header = ["group", "object", "label", "near"] + per_view
    rows = [header]
    for group, episodes in (("known", runs["known"][0]), ("unknown", runs["unknown"])):
        for i, (r, answered) in enumerate(zip(episodes, answers(episodes, STEPS))):
            per_view = [list(answered), r.prototypes, r.energies,
                        open_set.msp(r.probs) if r.probs else []]
            cells = [f"{v:.5g}" if isinstance(v, float) else str(v) for values in per_view
                     for v in (list(values) + [""] * STEPS)[:STEPS]]
            rows.append([group, i, r.label, int(bool(near[i])) if group == "unknown" and near is not None else 0]
                        + cells)
    return rows


def rule(rows, right, score="prototype_mean"):
    """The planner the stated rule names: of those whose mean accuracy is within one paired
    standard error of the best's, the one whose `score` (the node's: the checkpoint's open_set
    score; energy_mean for a checkpoint without class means) tells the val unknowns best after 10
    views. -> (planner, the planners tied with the best)."""
    best = max(rows, key=lambda p: rows[p]["mean"])
    lead = {p: paired(right, best, p) for p in rows if p != best}  # (best's lead, its s.e.)
    tied = [p for p in rows if p == best or lead[p][0] <= lead[p][1]]
    name = score if all(score in rows[p]["auroc"] for p in tied) else "energy_mean"
    return max(tied, key=lambda p: rows[p]["auroc"][name][-1]), tied


def ship(path, chosen, summary):
    """Record `chosen` as the default planner of the model at `path` and of its test summary."""
    checkpoint.update(path, default_planner=chosen)
    if summary.is_file():
        write_json(summary, {**json.loads(summary.read_text()), "default_planner": chosen,
                             "default_chosen_by": "validation_camera.json"})
    print(f"{path}: default planner {chosen}; its unknown thresholds are fitted for the planner auto "
          f"names: after a change, active-recognition open-set-fit --camera realsense")


def run(ap, args):
    if args.starts < 1 or args.objects < 0:
        ap.error("--starts must be at least 1 and --objects at least 0")
    for flag, asked in (("--planners", args.planners), ("--reference", [args.reference] if args.reference else [])):
        bad = sorted(set(asked) - set(CHOICES))
        if bad:
            ap.error(f"{flag}: {', '.join(bad)} not among the node's planners {', '.join(CHOICES)}")
    partial = [flag for flag, on in (("--objects", args.objects), ("--starts", args.starts != STARTS),
                                     ("--seed", args.seed != SEED), ("--checkpoint", args.checkpoint),
                                     ("--camera", args.camera != "realsense"),
                                     ("--planners", set(args.planners) != set(PLANNERS)),
                                     ("--reference", args.reference),
                                     ("--unknowns", args.unknowns != "real_unknowns")) if on]
    if args.ship and partial:
        ap.error(f"--ship records what the whole benchmark chose for the shipped model; leave out "
                 f"{', '.join(partial)}")
    committed = str(results_dir("modelnet") / "validation_camera.json")
    if args.ship and args.out is not None and Path(args.out).resolve() != Path(committed).resolve():
        ap.error(f"--ship records the choice beside its committed figures ({committed}); leave out --out")
    args.out = output(ap, args.out, committed, partial)
    path = checkpoint.model_path(args.checkpoint, "modelnet")
    model, _, ckpt = checkpoint.load_model(path)
    if model.open_set is None:
        print(f"{path}: carries no open_set (active-recognition open-set-fit): its prototype "
              f"score is not measured, and energy_mean breaks ties")
    default = args.reference or ckpt.get("default_planner") or "learned"
    val = open_splits("modelnet", args.root, ("val",), default_cache_dir())["val"]
    unknown = open_dataset(args.unknowns, args.unknowns_root, "val", cache_dir=default_cache_dir())
    nk, nu = (min(args.objects, len(d)) if args.objects else len(d) for d in (val, unknown))
    near = (np.array([is_near(unknown, i) for i in range(nu)])
            if args.unknowns == "real_unknowns" else None)
    rows, right = {}, {}
    for planner in dict.fromkeys((default, *args.planners)):
        runs = planner_runs(path, planner, ((val, "modelnet", args.root, nk),
                                            (unknown, args.unknowns, args.unknowns_root, nu)), args.camera,
                            args.starts, args.seed)
        right[planner], rows[planner] = summarise(runs, near)
        if args.scores and planner == default:
            with atomic_write(args.scores, newline="") as f:
                csv.writer(f).writerows(score_rows(runs, near))
        print(f"{planner}: after 3/6/9 views {rows[planner]['acc']}, mean {rows[planner]['mean']:.4f} "
              f"({rows[planner]['episodes']} episodes); AUROC after {AUROC_AT} views {rows[planner]['auroc']}"
              + (f"; near ones alone {rows[planner]['auroc_near']}" if "auroc_near" in rows[planner] else ""),
              flush=True)
    for planner in rows:
        rows[planner]["minus_default"], rows[planner]["minus_default_se"] = (
            round(v, 4) for v in paired(right, planner, default))
        print(f"{planner} - {default}: {100 * rows[planner]['minus_default']:+.2f} points, paired s.e. "
              f"{100 * rows[planner]['minus_default_se']:.2f}")
    chosen, tied = rule(rows, right, model.open_set["score"] if model.open_set is not None else "prototype_mean")
    record = {"camera": args.camera, "checkpoint": path.name, "unknowns": args.unknowns,
              "default": default, "starts": args.starts,
              "seed": args.seed, "known_objects": nk, "unknown_objects": nu, "planners": rows,
              "rule": {"chosen": chosen, "tied_with_the_best": tied}}
    print(f"rule: {chosen} (within one paired s.e. of the best mean: {', '.join(tied)}; of those the "
          f"best val AUROC after {STEPS} views)")
    if args.out:
        write_json(Path(args.out), record)
    if args.ship:
        ship(path, chosen, results_dir("modelnet") / "summary.json")
    emit({"chosen": chosen, **{p: rows[p]["acc"] for p in rows}})


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    add_common_flags(ap, "root", "checkpoint", root_required=True)
    ap.add_argument("--planners", nargs="+", default=list(PLANNERS), help="planners beside the default")
    ap.add_argument("--reference", default=None, help="the planner the others are paired against, run "
                    "beside them (default: the checkpoint's default_planner, learned where it names none; "
                    "--reference imitation --planners imitation runs imitation alone)")
    add_common_flags(ap, "starts", starts=STARTS, starts_help="seeded starts per val object")
    ap.add_argument("--seed", type=int, default=SEED, help=f"first start's seed (default {SEED})")
    ap.add_argument("--objects", type=int, default=0, help="the first N val objects of each group (0: all)")
    add_common_flags(ap, "camera")
    add_unknowns_flags(ap, default="real_unknowns")  # the planner is chosen beside real unknowns
    add_common_flags(ap, "out", out="docs/results/modelnet10/validation_camera.json")
    ap.add_argument("--scores", default=None, metavar="CSV", help="write the default planner's per-view "
                    "answers and scores of the first start, known and unknown, to this CSV")
    ap.add_argument("--ship", action="store_true", help="record the chosen planner as the shipped model's "
                    "default (the node's planner auto) and in docs/results/modelnet10/summary.json")
    args = ap.parse_args(argv)
    with one_line_errors(ap):
        run(ap, args)


if __name__ == "__main__":
    main()
