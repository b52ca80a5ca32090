# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""The `unknown` answer as the node gives it: known and unknown test objects through a simulated
camera and the recognizer's own path (SimulatedCamera -> ActiveRecognizer.observe, which
reprojects every image into the model's camera), with the node's defaults (the checkpoint's
stored thresholds and hold, object_size read, views from 0 to 90 degrees of elevation).

benchmarks/open_set_auroc.py measures the scores on the model's own renders; this one the shipped
operating point through a camera: `virtual` (64x64, no noise) or `realsense` (640x480, noise,
holes, 2 degrees of arm error). Known objects are ModelNet10's test split (or a seeded draw of
it), each at its own size; unknown ones the generated unknowns' test styles at their size as
built, or with `--unknowns real_unknowns` the real meshes' test split (datasets/real_unknowns.py,
rebuilt under --unknowns-root by tools/fetch_real_unknowns.py) at their size in metres, with the
furniture-like (`near`) ones also alone; each kept within 0.3 to 3 m (camera_episodes.py).
Prints, and writes to docs/results/modelnet10/open_set_camera.json (open_set_camera_real.json
for real unknowns; a partial run must give --out), the share of each
group answered `unknown`, the other statuses, the known accuracy (an `unknown` answer wrong),
and the AUROC and FPR@95 of the checkpoint's own running score (prototype_mean, or energy_mean
where its open_set says so, plus its size term: open_set.size_term) at each episode's end; and the first
three as a robot allowed 3, 6 or 9 classified images would have them (`cut`: the answer after
that image, `unknown` where the running score is above that step's threshold; an episode that
ended sooner as it ended). Last line is JSON.

    python benchmarks/open_set_camera.py --root ~/data/ModelNet10 [--unknowns real_unknowns --unknowns-root DIR]
"""
import argparse
from collections import Counter
from dataclasses import replace
from pathlib import Path

import numpy as np
from common import add_common_flags, add_unknowns_flags, emit, one_line_errors, output, results_dir

from active_recognition.datasets import default_cache_dir, open_dataset
from active_recognition.datasets.real_unknowns import near as is_near
from active_recognition.evaluation.camera_episodes import camera_runs, robot_cost
from active_recognition.evaluation.evaluate import EvalConfig
from active_recognition.evaluation.report import write_json
from active_recognition.model import checkpoint
from active_recognition.options.flags_and_parameters import add_flags
from active_recognition.options.recognizer_params import RecognizerParameters
from active_recognition.runtime.active_recognizer import ActiveRecognizer
from active_recognition.unknown import scores as open_set

OBJECTS_DEFAULT = 0  # of each group: 0 = every one (899 known, 450 generated or 83 real unknowns)
CUTS = (3, 6, 9)


def cut(run, t, thresholds, score="prototype_mean"):
    """(answered unknown, answered right) of a CameraRun cut after its t-th classified image,
    against per-step thresholds on `score` (its views' prototypes, or energies for energy_mean;
    the checkpoint's for the run's size: open_set.own_thresholds); a run with no more images than
    t as it ended."""
    if len(run.probs) <= t:
        return run.status == "unknown", run.right
    views = run.energies if score == "energy_mean" else run.prototypes
    flagged = float(np.mean(views[:t])) > open_set.step_thresholds(thresholds, t)[-1]
    return flagged, not flagged and int(np.argmax(run.probs[t - 1])) == run.label


def run(ap, args):
    partial = [flag for flag, on in (("--objects", args.objects != OBJECTS_DEFAULT), ("--seed", args.seed),
                                     ("--checkpoint", args.checkpoint), ("--camera", args.camera != "realsense"),
                                     ("--unknowns-root", args.unknowns != "real_unknowns" and args.unknowns_root),
                                     ("--no-size", args.no_size))
               if on]
    name = "open_set_camera_real.json" if args.unknowns == "real_unknowns" else "open_set_camera.json"
    args.out = output(ap, args.out, str(results_dir("modelnet") / name), partial)
    path = checkpoint.model_path(args.checkpoint, "modelnet")
    model = checkpoint.load_model(path)[0]
    if model.open_set is None:
        ap.error(f"{path}: carries no open_set (active-recognition open-set-fit)")
    node = RecognizerParameters()  # the node's defaults
    sensing = replace(node.sensing, use_size=False) if args.no_size else node.sensing
    core = ActiveRecognizer(str(path), node.episode, args.seed, node.node.planner, sensing, node.limits)

    def size(run):  # the size the recognizer is told, None where it is not
        return None if args.no_size else run.size

    groups, cuts, costs = {}, {}, {}
    if args.objects < 0:
        ap.error("--objects must be 0 (all) or more")
    sources = (("known", "modelnet", args.root), ("unknown", args.unknowns, args.unknowns_root))
    # both opened before any episode, the unknowns' first: their root is the one most often missing
    opened = {g: open_dataset(d, r, "test", cache_dir=default_cache_dir()) for g, d, r in sources[::-1]}
    for group, dataset, root in sources:
        test = opened[group]
        objects = np.sort(np.random.default_rng(args.seed).permutation(len(test))[:args.objects or len(test)])
        if group == "unknown":
            near = np.array([dataset == "real_unknowns" and is_near(test, i) for i in objects])
        runs = camera_runs(core, test, dataset, "test", objects, args.camera, args.seed, root, record=True)
        groups[group] = ([r.status for r in runs], [r.right for r in runs],
                         np.array([r.score + open_set.size_term(model, size(r)) for r in runs]),
                         [test.classes[test.items[int(i)][1]] for i in objects])
        costs[group] = {k: round(v, digits) for (k, v), digits in zip(robot_cost(runs).items(), (3, 1, 2, 2))}
        cuts[group] = {t: np.array([cut(r, t, open_set.own_thresholds(model, size(r)), model.open_set["score"])
                                    for r in runs])
                       for t in CUTS}
    (ks, kr, kscore, _), (us, _, uscore, _) = groups["known"], groups["unknown"]
    seen = np.isfinite(kscore), np.isfinite(uscore)
    record = {"camera": args.camera, "checkpoint": path.name, "planner": core.planner, "unknowns": args.unknowns,
              "objects": {g: len(groups[g][0]) for g in groups},
              "seed": args.seed, "known_rejected": round(float(np.mean(np.array(ks) == "unknown")), 4),
              "unknown_flagged": round(float(np.mean(np.array(us) == "unknown")), 4),
              "known_accuracy": round(float(np.mean(kr)), 4),
              "statuses": {g: dict(Counter(groups[g][0])) for g in groups},
              "score": model.open_set["score"],  # the checkpoint's own, the AUROCs' and the cut's
              "size_weight": model.open_set.get("size_weight", 0.0), "use_size": not args.no_size,
              "auroc": round(open_set.auroc(kscore[seen[0]], uscore[seen[1]]), 4),
              "fpr95": round(open_set.fpr_at(kscore[seen[0]], uscore[seen[1]]), 4),
              "cut": {name: {str(t): round(float(cuts[g][t][:, col].mean()), 4) for t in CUTS}
                      for name, g, col in (("known_rejected", "known", 0), ("unknown_flagged", "unknown", 0),
                                           ("known_accuracy", "known", 1))},
              "episode": vars(node.episode), "cost": costs}
    if near.any():  # the furniture-like unknowns alone
        record["near"] = {"objects": int(near.sum()),
                          "unknown_flagged": round(float(np.mean(np.array(us)[near] == "unknown")), 4),
                          "auroc": round(open_set.auroc(kscore[seen[0]], uscore[near & seen[1]]), 4),
                          "classes": dict(Counter(np.array(groups["unknown"][3])[near]))}
    print(f"{args.camera}: known answered unknown {record['known_rejected']:.1%}, unknown answered unknown "
          f"{record['unknown_flagged']:.1%}, known accuracy {record['known_accuracy']:.1%}; AUROC "
          f"{record['auroc']:.3f}, FPR@95 {record['fpr95']:.3f}; statuses {record['statuses']}; cut after "
          f"{'/'.join(map(str, CUTS))} images: {record['cut']}"
          + (f"; near unknowns ({record['near']['objects']}): answered unknown {record['near']['unknown_flagged']:.1%}"
             f", AUROC {record['near']['auroc']:.3f}" if "near" in record else ""))
    if args.out:
        write_json(Path(args.out), record)
    print(f"views, travel and robot seconds (robot_time's defaults): {costs}")
    emit({k: v for k, v in record.items() if k not in ("statuses", "cut", "near", "objects", "episode", "cost")})


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    add_common_flags(ap, "root", "checkpoint", root_required=True)
    add_flags(ap, EvalConfig, ["seed"])
    ap.add_argument("--objects", type=int, default=OBJECTS_DEFAULT,
                    help="known and unknown test objects each (a seeded draw; default 0: every one)")
    add_common_flags(ap, "camera")
    add_unknowns_flags(ap)
    ap.add_argument("--no-size", action="store_true", help="the recognizer not told the objects' sizes "
                    "(use_size false: no size prior, no size term in the unknown score)")
    add_common_flags(ap, "out", out="docs/results/modelnet10/open_set_camera.json, open_set_camera_real.json "
                     "with --unknowns real_unknowns")
    args = ap.parse_args(argv)
    with one_line_errors(ap):
        run(ap, args)


if __name__ == "__main__":
    main()
