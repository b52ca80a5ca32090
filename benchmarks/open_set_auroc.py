# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""Open-set recognition: how well each score (active_recognition/unknown/scores.py) tells objects of
no known class from known ones.

Known objects are the dataset's test split; unknown ones the generated `unknowns` of their test
styles (datasets/unknowns.py). The operating point of each score is chosen on validation only:
the dataset's val split (a seeded tenth of train) and the unknowns of their val styles, which no
test object shares. The Mahalanobis Gaussians are fitted, one per step, on the recurrent states
of a seeded sample of the training split less val; their means are the prototypes. Every
episode is evaluate.rollout's, run by the recognizer's planner (--planner auto: the checkpoint's
default), reading each object's size as the recognizer does by default (use_size): the known
objects' from their files, the generated unknowns' as built, in metres (--no-size: the images
alone). Views come from the whole sphere, the paper's setting, unless --min-elevation bars those
below it (0: a camera over the floor the object stands on, as the node's default limits).

Prints, after 1 to --steps views, each score's AUROC and FPR@95 (the share of unknown objects
accepted when 95 % of known ones are); then, at the operating point that accepts --known-rate of
the known validation objects after 3, 6 and 9 views, the share of known test objects answered
unknown, the share of unknown ones answered unknown, and the known accuracy counting an unknown
answer as wrong. Where the checkpoint carries its own open_set (active-recognition
open-set-fit), the same three at its stored per-step thresholds as the
recognizer answers (its hold: a confident answer that looks unknown waits), in episodes cut after
3, 6 and 9 views and at their end (key `stored`), and the same for episodes of --compare's
planner (default random: what choosing the views adds; key `compared`). Writes
docs/results/modelnet10/open_set.json (a partial run must give --out); the last line is JSON.

    python benchmarks/open_set_auroc.py --dataset modelnet --root ~/data/ModelNet10 [--objects 50 --out F]
"""
import argparse
from pathlib import Path

import numpy as np
from common import add_common_flags, emit, one_line_errors, output, results_dir

from active_recognition.argument_checks import InputError
from active_recognition.datasets import default_cache_dir, open_dataset, open_splits, subset_with_every_class
from active_recognition.datasets.shapes import Shapes
from active_recognition.evaluation.evaluate import EvalConfig, checkpoint_split, sample_episodes
from active_recognition.evaluation.report import write_json
from active_recognition.model import checkpoint
from active_recognition.options.flags_and_parameters import add_flags
from active_recognition.sensing.reach import ViewLimits
from active_recognition.unknown import scores as open_set
from active_recognition.unknown.fit import episodes, node_planner, running

VIEWS = (3, 6, 9)
FIT_OBJECTS = 600  # training objects whose states the Gaussians are fitted on


def r4(x):
    return round(float(x), 4)


def size_terms(model, shapes, ro, size):
    """(N,) each episode's size term (open_set.size_term: what its object's size adds to its
    energy_mean before the thresholds are read); 0 where sizes are not read (--no-size)."""
    sizes = shapes.sizes(ro.objects) if size else None
    if sizes is None:
        return np.zeros(len(ro.objects))
    return np.array([open_set.size_term(model, s) for s in sizes])


def stored_point(entry, known, unknown, entropy_threshold, terms=(0.0, 0.0)):
    """The operating point of the checkpoint's own open_set (its score, prototype_mean against its
    class means or energy_mean, and per-step thresholds) on the test runs known and unknown
    ((Rollout, record) each), as the recognizer answers under its hold (a confident answer that
    looks unknown waits): known
    rejected, unknown flagged and known accuracy (an unknown answer wrong) of the episodes cut
    after 3, 6 and 9 views (max_views k) and at their end (`end`); `unheld`: at the end of the
    entropy stop without the hold. terms: the known and unknown episodes' size terms (size_terms)."""
    means = entry["means"].numpy()
    (kro, krec), (uro, urec) = known, unknown
    ks, us = (running(entry["score"], r["states"], r["logits"], means) + np.reshape(t, (-1, 1))
              for r, t in ((krec, terms[0]), (urec, terms[1])))
    steps = ks.shape[1]
    thr = open_set.step_thresholds(entry["threshold"], steps)
    right = kro.probs.argmax(-1) == kro.labels[:, None]
    out = {key: {} for key in ("known_rejected", "unknown_flagged", "known_accuracy")}

    def point(key, kend, uend):  # the three shares of the episodes ending at kend and uend (1-based)
        krej = open_set.answered_unknown(ks, kend, thr)
        out["known_rejected"][key] = r4(krej.mean())
        out["unknown_flagged"][key] = r4(open_set.answered_unknown(us, uend, thr).mean())
        out["known_accuracy"][key] = r4((open_set.at_end(right, kend) & ~krej).mean())

    for key, k in ({str(k): k for k in VIEWS if k <= steps} | {"end": steps}).items():
        point(key, *(open_set.held_stops(ro.probs[:, :k], sc[:, :k], entropy_threshold, thr[:k])
                     for ro, sc in ((kro, ks), (uro, us))))
    point("unheld", kro.stopped_at, uro.stopped_at)  # the entropy stop alone, no hold
    return {"threshold": [r4(t) for t in thr], "fitted_on": entry.get("fitted_on", {}), **out}


def measure(known, unknown, steps):
    """{score: AUROC by views}, {score: FPR@95 by views} of known and unknown scores (N, T)."""
    auroc = {s: [r4(open_set.auroc(known[s][:, t], unknown[s][:, t])) for t in range(steps)] for s in known}
    fpr = {s: [r4(open_set.fpr_at(known[s][:, t], unknown[s][:, t])) for t in range(steps)] for s in known}
    return auroc, fpr


def operating(val_known, test_known, test_unknown, ro, rate):
    """At each score's threshold accepting `rate` of the known val objects after k views: its
    thresholds, and the test's known rejected, unknown flagged and known accuracy (an unknown
    answer wrong), each {score: {k: share}}."""
    out = {key: {} for key in ("operating_point", "known_rejected", "unknown_flagged", "known_accuracy")}
    right = ro.probs.argmax(-1) == ro.labels[:, None]
    for s in val_known:
        views = [k for k in VIEWS if k <= ro.probs.shape[1]]
        thr = {k: open_set.threshold_at(val_known[s][:, k - 1], rate) for k in views}
        out["operating_point"][s] = {str(k): r4(t) for k, t in thr.items()}
        out["known_rejected"][s] = {str(k): r4((test_known[s][:, k - 1] > thr[k]).mean()) for k in views}
        out["unknown_flagged"][s] = {str(k): r4((test_unknown[s][:, k - 1] > thr[k]).mean()) for k in views}
        out["known_accuracy"][s] = {str(k): r4((right[:, k - 1] & (test_known[s][:, k - 1] <= thr[k])).mean())
                                    for k in views}
    return out


def by_kind(run, score, thresholds):
    """{kind: share of its unknown objects answered unknown} at the last of the views thresholded."""
    ro, scores = run
    k = max(int(v) for v in thresholds)
    flagged = scores[score][:, k - 1] > thresholds[str(k)]
    return {kind: r4(flagged[ro.labels == i].mean()) for i, kind in enumerate(ro.classes) if (ro.labels == i).any()}


def run(args):
    path = checkpoint.model_path(args.checkpoint, args.dataset)
    cfg = EvalConfig(checkpoint=str(path), dataset=args.dataset, root=args.root, split="test",
                     steps=args.steps, seed=args.seed, size=args.size, shared=False,
                     limits=ViewLimits(args.min_elevation))
    model, classes, test, _ = checkpoint_split(str(path), cfg)
    parts = open_splits(args.dataset, args.root, ("train", "val"), default_cache_dir())
    train, val = (Shapes(parts[s], test.camera) for s in ("train", "val"))
    unknown = {s: Shapes(open_dataset("unknowns", split=s, cache_dir=default_cache_dir()), test.camera)
               for s in ("val", "test")}
    fit_n = min(args.fit_objects, len(train))
    if fit_n < len(classes):
        raise InputError(f"fit_objects = {args.fit_objects}: the Gaussians need a training object of each of "
                         f"the {len(classes)} classes")
    planner, fixed_path = node_planner(args.planner, model, checkpoint.read(path))
    fit_ro, fit_rec = episodes(planner, model, train, subset_with_every_class(train.labels, fit_n, args.seed),
                               cfg, fixed_path)
    gaussians = open_set.fit_steps(fit_rec["states"], fit_ro.labels, len(classes), args.shrink)
    runs, recs = {}, {}
    for name, shapes in (("known_test", test), ("unknown_test", unknown["test"]), ("known_val", val),
                         ("unknown_val", unknown["val"])):
        if args.objects > len(shapes):
            raise InputError(f"objects = {args.objects}, but {name} holds {len(shapes)} (0 = all of them)")
        objects, _ = sample_episodes(args.objects, len(shapes), 1, args.seed)
        ro, rec = episodes(planner, model, shapes, objects, cfg, fixed_path)
        runs[name], recs[name] = (ro, open_set.scores(rec, gaussians)), (ro, rec)
        print(f"{name}: {len(ro.objects)} objects", flush=True)
    sc = {name: s for name, (_, s) in runs.items()}
    auroc, fpr = measure(sc["known_test"], sc["unknown_test"], args.steps)
    val_auroc, _ = measure(sc["known_val"], sc["unknown_val"], args.steps)
    chosen = max(val_auroc, key=lambda s: val_auroc[s][-1])  # on validation, at the episode's end
    ro = runs["known_test"][0]
    record = {"dataset": args.dataset, "checkpoint": path.name, "planner": planner, "size": args.size,
              "min_elevation": args.min_elevation,
              "objects": {name: len(r[0].objects) for name, r in runs.items()} | {"fit": fit_n},
              "known_rate": args.known_rate, "shrink": args.shrink, "auroc": auroc, "fpr95": fpr,
              "val_auroc": val_auroc, "chosen": chosen,
              "closed_set_accuracy": {str(k): r4(ro.accuracy()[k - 1]) for k in VIEWS if k <= args.steps}}
    record |= operating(sc["known_val"], sc["known_test"], sc["unknown_test"], ro, args.known_rate)
    record["unknown_flagged_by_kind"] = by_kind(runs["unknown_test"], chosen, record["operating_point"][chosen])
    if model.open_set is not None:  # the checkpoint's own operating point (unknown/fit.py)
        terms = [size_terms(model, shapes, recs[name][0], args.size)
                 for name, shapes in (("known_test", test), ("unknown_test", unknown["test"]))]
        entry = model.open_set if terms[0].any() else {  # no size term: the thresholds fitted without one
            **model.open_set, "threshold": open_set.own_thresholds(model, None)}
        record["stored"] = stored_point(entry, recs["known_test"], recs["unknown_test"], cfg.entropy_threshold, terms)
        if args.compare != planner:  # what the planner's choice of views adds: the same, another planner's
            other = {name: episodes(args.compare, model, shapes, objects, cfg, fixed_path)
                     for name, (shapes, objects) in (("known", (test, recs["known_test"][0].objects)),
                                                     ("unknown", (unknown["test"], recs["unknown_test"][0].objects)))}
            means = model.open_set["means"].numpy()
            ks, us = ({"prototype_mean": open_set.prototype_mean(other[g][1]["states"], means)}
                      for g in ("known", "unknown"))
            c_auroc, c_fpr = measure(ks, us, args.steps)
            record["compared"] = {"planner": args.compare, "auroc": c_auroc["prototype_mean"],
                                  "fpr95": c_fpr["prototype_mean"],
                                  "stored": stored_point(entry, other["known"], other["unknown"],
                                                         cfg.entropy_threshold, terms)}
    print_tables(record, args.steps)
    if args.out != "":
        write_json(Path(args.out), record)
    emit({k: record[k] for k in ("auroc", "fpr95", "known_rejected", "unknown_flagged", "known_accuracy")}
         | {"chosen": chosen} | {k: record[k] for k in ("stored", "compared") if k in record})


def print_tables(record, steps):
    head = "".join(f"{t:>7}" for t in range(1, steps + 1))
    for key in ("auroc", "fpr95"):
        print(f"{key} after 1..{steps} views\n{'score':<18}{head}")
        for s, row in record[key].items():
            print(f"{s:<18}" + "".join(f"{v:>7.3f}" for v in row))
    print(f"at the operating point (accepting {record['known_rate']:.0%} of known val objects): "
          f"known rejected / unknown flagged / known accuracy after {', '.join(map(str, VIEWS))} views")
    for s in record["known_rejected"]:
        cells = [f"{record[k][s][v]:.3f}" for v in record["known_rejected"][s]
                 for k in ("known_rejected", "unknown_flagged", "known_accuracy")]
        print(f"{s:<18}" + "  ".join(" / ".join(cells[i:i + 3]) for i in range(0, len(cells), 3)))
    print(f"closed-set accuracy {record['closed_set_accuracy']}; chosen on val: {record['chosen']}")
    print(f"{record['chosen']}: unknown objects answered unknown, by kind: {record['unknown_flagged_by_kind']}")
    for name, st in (("the checkpoint's stored operating point", record.get("stored")),
                     (f"the same with {record.get('compared', {}).get('planner')} views",
                      record.get("compared", {}).get("stored"))):
        if st is not None:
            score = st.get("fitted_on", {}).get("score", "prototype_mean")
            print(f"{name} ({score} above {st['threshold']} by views): known rejected / unknown "
                  f"flagged / known accuracy, cut after " + ", ".join(
                      f"{k}: {st['known_rejected'][k]:.3f} / {st['unknown_flagged'][k]:.3f} / "
                      f"{st['known_accuracy'][k]:.3f}" for k in st["known_rejected"]))
    if "compared" in record:
        print(f"prototype_mean with {record['compared']['planner']} views: AUROC {record['compared']['auroc']}, "
              f"FPR@95 {record['compared']['fpr95']}")


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    flags = ["dataset", "root", "checkpoint", "objects", "seed", "steps", "size", "min_elevation"]
    add_flags(ap, EvalConfig, flags, dataset={
        "choices": ("procedural", "modelnet"), "default": "modelnet", "help": "the known objects' dataset"},
        objects={"help": "seeded sample of each of the four splits' objects (0: all)"})
    ap.add_argument("--planner", default="auto", help=(
        "the planner of every episode (default auto: the recognizer's, the checkpoint's own)"))
    ap.add_argument("--compare", default="random", help=(
        "a planner whose test episodes are scored the same way beside it, at the stored operating "
        "point (default random: what choosing the views adds)"))
    ap.add_argument("--fit-objects", type=int, default=FIT_OBJECTS,
                    help=f"training objects the Mahalanobis Gaussians are fitted on (default {FIT_OBJECTS})")
    ap.add_argument("--shrink", type=float, default=open_set.SHRINK,
                    help=f"covariance shrinkage toward the identity, in [0, 1] (default {open_set.SHRINK})")
    ap.add_argument("--known-rate", type=float, default=0.95,
                    help="share of known validation objects the operating point accepts (default 0.95)")
    add_common_flags(ap, "out", out="docs/results/modelnet10/open_set.json for modelnet")
    args = ap.parse_args(argv)
    if not 0 < args.known_rate <= 1:
        ap.error(f"--known-rate must lie in (0, 1], got {args.known_rate}")
    if not 0 <= args.shrink <= 1:
        ap.error(f"--shrink must lie in [0, 1], got {args.shrink}")
    partial = [f for f, on in (("--objects", args.objects), ("--fit-objects", args.fit_objects != FIT_OBJECTS),
                               ("--seed", args.seed), ("--steps", args.steps != 10),
                               ("--min-elevation", args.min_elevation != ViewLimits().min_elevation)) if on]
    args.out = output(ap, args.out, str(results_dir(args.dataset) / "open_set.json"), partial)
    with one_line_errors(ap):  # a bad root or model file: one line, not a traceback
        run(args)


if __name__ == "__main__":
    main()
