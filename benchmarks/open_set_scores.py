# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""Which `unknown` score tells real objects of other classes from ModelNet10's, as the node
sees them: every episode shot through a simulated camera and the recognizer's own path
(camera_episodes.py), 10 views each from a seeded start, no stop and no hold, its recurrent state
recorded after every view. The states of --objects training objects (the training split less
val, every class in the sample) are the reference; the val split's known objects and the real
unknowns' val split (or the generated unknowns' val styles) are scored against it. Test objects
are never read.

Scores (higher = more likely unknown), each per view and as its running mean (`_mean`):
- `prototype`: 1 - the largest cosine similarity of the state to a class mean of that step's
  training states (the node's score, active_recognition/unknown/scores.py);
- `knn1`, `knn3`, `knn10`: 1 - the cosine similarity to the k-th nearest training state of that
  step (a deep nearest-neighbour score, Sun et al. 2022: blind to how a class's objects spread).
For each, after 3, 6 and 10 views: the AUROC (known against unknown) and the share of unknowns
above the threshold that rejects 3 % and 5 % of the known ones; and for prototype_mean the same
with a threshold per answered class (`per_class`: each class's own 97th / 95th percentile, fitted
on one half of the known objects and applied to the other, two folds: the known share rejected
is measured, not assumed), beside one threshold for all that rejects that measured share.
Writes docs/results/modelnet10/open_set_scores.json (a partial run must give --out); last line JSON.

    python benchmarks/open_set_scores.py --root ~/data/ModelNet10 --unknowns-root ~/data/real_unknowns
        [--checkpoint PATH] [--objects 600] [--unknowns unknowns]
"""
import argparse

import numpy as np
from common import add_common_flags, add_unknowns_flags, emit, one_line_errors, output, results_dir

from active_recognition.datasets import default_cache_dir, open_dataset, open_splits, subset_with_every_class
from active_recognition.evaluation.camera_episodes import camera_runs, full_length, recording_core
from active_recognition.evaluation.report import write_json
from active_recognition.model import checkpoint
from active_recognition.unknown import scores as open_set
from active_recognition.unknown.fit import prototype_means

STEPS = 10
AT = (3, 6, 10)
RATES = (0.03, 0.05)
KS = (1, 3, 10)
FIT_OBJECTS = 600


def unit(x):
    return x / np.maximum(np.linalg.norm(x, axis=-1, keepdims=True), 1e-12)


def knn(reference, states, k):
    """(N, T) 1 - the cosine similarity of each state (N, T, S) to the k-th nearest of the
    reference states of its step (M, T, S)."""
    out = []
    for t in range(states.shape[1]):
        distance = 1.0 - unit(states[:, t]) @ unit(reference[:, t]).T
        out.append(np.sort(distance, 1)[:, k - 1])
    return np.stack(out, 1)


def all_scores(reference, labels, states, classes):
    """{score: (N, T)} of states (N, T, S) against the reference states (M, T, S) with labels."""
    means = prototype_means(reference, labels, classes)
    out = {"prototype": open_set.prototype_steps(states, means)}
    out.update({f"knn{k}": knn(reference, states, k) for k in KS})
    out.update({f"{name}_mean": open_set.running_mean(s) for name, s in list(out.items())})
    return out


def flagged_at(known, unknown, rate):
    """The share of unknown scores above the threshold that rejects `rate` of the known ones."""
    return float((np.asarray(unknown) > np.quantile(known, 1 - rate)).mean())


def per_class(known, known_answers, unknown, unknown_answers, rate, seed=0, classes=10):
    """(known share rejected, unknown share flagged) with a threshold per answered class, each
    class's (1 - rate) quantile of the known scores answered so, fitted on one half of the known
    objects and applied to the other half and to the unknowns (two folds, seeded); a class with
    fewer than 4 fitted scores rejects nothing."""
    fold = np.random.default_rng(seed).integers(0, 2, len(known))
    rejected, flagged = np.zeros(len(known), bool), []
    for f in (0, 1):
        fit = fold != f
        thr = np.array([np.quantile(known[fit & (known_answers == c)], 1 - rate)
                        if (fit & (known_answers == c)).sum() >= 4 else np.inf for c in range(classes)])
        rejected[~fit] = known[~fit] > thr[known_answers[~fit]]
        flagged.append(unknown > thr[unknown_answers])
    return float(rejected.mean()), float(np.mean(flagged))


def table(known, unknown):
    """The figures of every score: AUROC and flagged shares after AT views; per_class for
    prototype_mean."""
    rows = {}
    for name in known["scores"]:
        k, u = known["scores"][name], unknown["scores"][name]
        rows[name] = {f"{t}": {"auroc": round(open_set.auroc(k[:, t - 1], u[:, t - 1]), 4),
                               **{f"flagged_at_{round(r * 100)}pc": round(flagged_at(k[:, t - 1], u[:, t - 1], r), 4)
                                  for r in RATES}} for t in AT}
    for t in AT:
        k, u = known["scores"]["prototype_mean"][:, t - 1], unknown["scores"]["prototype_mean"][:, t - 1]
        for r in RATES:
            rej, flag = per_class(k, known["answers"][:, t - 1], u, unknown["answers"][:, t - 1], r)
            pc = round(r * 100)
            rows.setdefault("prototype_mean per_class", {}).setdefault(f"{t}", {}).update(
                {f"known_rejected_at_{pc}pc": round(rej, 4), f"flagged_at_{pc}pc": round(flag, 4),
                 f"one_threshold_flagged_at_{pc}pc_rate": round(flagged_at(k, u, rej), 4)})
    return rows


def recorded(core, ds, name, split, objects, preset, seed, root):
    """{"states": (N, T, S), "answers": (N, T), "labels": (N,)} of the runs that took STEPS images."""
    probs, states, whole = full_length(camera_runs(core, ds, name, split, objects, preset, seed, root, record=True),
                                       STEPS)
    return {"states": states, "answers": probs.argmax(-1), "labels": np.array([r.label for r in whole])}


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    add_common_flags(ap, "root", root_required=True)
    # --checkpoint by hand: its default names the shipped model (EvalConfig's is None), which the JSON records
    ap.add_argument("--checkpoint", default="modelnet10.pt", help="the model (default: the shipped one)")
    ap.add_argument("--objects", type=int, default=FIT_OBJECTS, help=f"training objects (default {FIT_OBJECTS})")
    ap.add_argument("--val-objects", type=int, default=0, help="seeded sample of the val objects, each group (0: all)")
    add_common_flags(ap, "camera")
    ap.add_argument("--seed", type=int, default=0)
    add_unknowns_flags(ap, default="real_unknowns")  # real meshes: a figure on generated ones is never the headline
    add_common_flags(ap, "out", out="docs/results/modelnet10/open_set_scores.json")
    args = ap.parse_args(argv)
    partial = [f for f, on in (("--checkpoint", args.checkpoint != "modelnet10.pt"),
                               ("--objects", args.objects != FIT_OBJECTS), ("--val-objects", args.val_objects),
                               ("--camera", args.camera != "realsense"), ("--seed", args.seed),
                               ("--unknowns", args.unknowns != "real_unknowns")) if on]
    if args.objects < 10:
        ap.error(f"--objects must be at least 10 (a training object of each class), got {args.objects}")
    if args.val_objects < 0:
        ap.error(f"--val-objects must be 0 (all) or more, got {args.val_objects}")
    out = output(ap, args.out, results_dir("modelnet") / "open_set_scores.json", partial)
    with one_line_errors(ap):
        path = checkpoint.model_path(args.checkpoint, "modelnet")
        core = recording_core(path, "auto", STEPS, args.seed)
        parts = open_splits("modelnet", args.root, ("train", "val"), default_cache_dir())
        odd = open_dataset(args.unknowns, args.unknowns_root, "val", cache_dir=default_cache_dir())
        rng = np.random.default_rng(args.seed)
        pick = lambda ds: np.sort(rng.permutation(len(ds))[:args.val_objects or len(ds)])  # noqa: E731
        train = parts["train"]
        fit_on = subset_with_every_class(np.array([label for _, label in train.items]), args.objects, args.seed)
        groups = {"train": recorded(core, train, "modelnet", "train", fit_on, args.camera, args.seed, args.root),
                  "known": recorded(core, parts["val"], "modelnet", "val", pick(parts["val"]), args.camera,
                                    args.seed, args.root),
                  "unknown": recorded(core, odd, args.unknowns, "val", pick(odd), args.camera, args.seed,
                                      args.unknowns_root)}
    ref = groups["train"]
    for g in ("known", "unknown"):
        groups[g]["scores"] = all_scores(ref["states"], ref["labels"], groups[g]["states"], len(train.classes))
    result = {"checkpoint": str(args.checkpoint), "camera": args.camera, "unknowns": args.unknowns, "seed": args.seed,
              "objects": {g: int(len(v["states"])) for g, v in groups.items()},
              "scores": table(groups["known"], groups["unknown"])}
    if out:
        write_json(out, result)
    for name, row in result["scores"].items():
        print(f"{name:26s} " + " | ".join(f"{t} views: " + ", ".join(f"{k} {v:.3f}" for k, v in fig.items())
                                          for t, fig in row.items()))
    emit(result)


if __name__ == "__main__":
    main()
