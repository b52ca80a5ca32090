# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""Fit a model's `unknown` answer and store it in its checkpoint (the key `open_set`).

The score (--score) is scores.py's `prototype_mean` (the default): the running mean, over the views
an episode has taken, of 1 - the largest cosine similarity of the step's recurrent state to a
class mean of that step; or `energy_mean`, the running mean of each view's energy (-log sum exp
of its logits), for a model whose training taught it to be unsure of objects of no known class
(outlier exposure). The class means are fitted and stored either way.
The per-step class means (steps, classes, state size) are fitted on the states of episodes of
--objects training objects (the training split less val, each class in the sample), each run by
--planner (default auto: the recognizer's own, the checkpoint's default planner) from a seeded
initial view, reading each object's size where the model has a size prior (as the recognizer's
use_size does by default; --no-size: from the images alone). The thresholds, one per number of views, are chosen on the
known validation objects (the dataset's val split) under the recognizer's hold (hold_unknown: a
confident answer waits while the score is above its step's threshold): cut after any number of
views, no more than 1 - --known-rate of their episodes end `unknown` (scores.held_thresholds;
the default 0.97 rejects about 3 %, a margin below the 5 % the test split may lose). The
unknowns' val styles (datasets/unknowns.py) are scored beside them and their share flagged kept
in `fitted_on`; their test styles are never read. With --camera PRESET the val episodes, and
the training episodes of a second set of means, are shot through that simulated camera and the
recognizer's own path (camera_episodes.py), as the node will see them: the thresholds are
chosen on those, and the means are whichever set tells the val unknowns better. With
--unknowns real_unknowns the val unknowns are real meshes (datasets/real_unknowns.py) in place
of the generated ones. With --score energy_mean through a camera, --size-weights W... adds a
size term to the score, each val episode's weight x the size prior's surprise at its object's size
(scores.size_term), the weight that flags the most val unknowns kept and the thresholds fitted
without it stored beside (for a recognizer not told the size); off by default (docs/training.md).
The checkpoint is rewritten atomically.

    active-recognition open-set-fit --checkpoint PATH --dataset modelnet --root DIR
        [--objects 600] [--known-rate 0.97] [--camera realsense] [--unknowns real_unknowns
        --unknowns-root DIR] [--score prototype_mean|energy_mean] [--size-weights W ...] [--out PATH]
"""
from __future__ import annotations

import argparse
import sys

import numpy as np
import torch

from active_recognition.argument_checks import InputError
from active_recognition.datasets import (
    OPEN_SET, default_cache_dir, open_dataset, open_splits, subset_with_every_class,
)
from active_recognition.datasets.shapes import Shapes
from active_recognition.evaluation.evaluate import EvalConfig
from active_recognition.model import checkpoint
from active_recognition.model.episode import ROBOT
from active_recognition.options.flags_and_parameters import add_flags
from active_recognition.sensing.depth_layer import CameraConfig
from active_recognition.simulation.depth_sensor import PRESETS
from active_recognition.unknown import scores
from active_recognition.unknown.thresholds import OPEN_SET_SCORE, OPEN_SET_SCORES, checked_open_set

FIT_OBJECTS = 600  # training objects whose states the means are fitted on
KNOWN_RATE = 0.97
SIZE_WEIGHTS = (0.0,)  # the size term's weights tried by default: none (energy_mean through a camera only)
SIZE_GRID = (0.0, 0.25, 0.5, 1.0, 2.0, 4.0)  # a grid to try: --size-weights 0 0.25 0.5 1 2 4


def episodes(planner, model, shapes, objects, cfg, fixed_path=None):
    """(Rollout, record of logits and states) of one episode per object, each from a seeded start
    (`fixed_path`: the fixed planners' path, a checkpoint's 'fixed_path')."""
    starts = np.random.default_rng(cfg.seed).integers(0, len(cfg.limits.initial_views(50)), len(objects))
    return recorded_rollout(planner, model, shapes, np.asarray(objects), starts, cfg, fixed_path=fixed_path)


def node_planner(name, model, ckpt):
    """(planner, fixed path) the recognizer would run for `name` ("auto": the checkpoint's own)."""
    from active_recognition.runtime.active_recognizer import choose_planner

    return choose_planner(name, model, ckpt), ckpt.get("fixed_path")


def prototype_means(states, labels, num_classes):
    """Per-step class means (T, C, S) float32 of states (N, T, S) with labels (N,)."""
    states, labels = np.asarray(states), np.asarray(labels)
    missing = sorted(set(range(num_classes)) - set(labels.tolist()))
    if missing:
        raise InputError(f"open_set means: no training state of class(es) {missing}")
    return np.stack([states[labels == c].mean(0) for c in range(num_classes)], 1).astype(np.float32)


def running(score, states, logits, means):
    """(N, T) the running `score` of episodes' states (N, T, S) against `means`, or of their
    per-step logits (N, T, C) (energy_mean)."""
    if score == "energy_mean":
        return scores.running_mean(scores.energy(logits))
    return scores.prototype_mean(states, means)


def scored(planner, model, shapes, objects, cfg, means, fixed_path=None, score=OPEN_SET_SCORE):
    """(probs (N, T, C), running score (N, T)) of episodes of `objects` (prototype_mean against `means`)."""
    ro, rec = episodes(planner, model, shapes, objects, cfg, fixed_path)
    return ro.probs, running(score, rec["states"], rec["logits"], means)


def flagged(probs, running, entropy_threshold, thresholds):
    """(N,) bool: the episodes the recognizer's hold ends `unknown` (their score above their
    last step's threshold)."""
    return scores.answered_unknown(running, scores.held_stops(probs, running, entropy_threshold, thresholds),
                                   thresholds)


def fit(path, dataset, root=None, objects=FIT_OBJECTS, known_rate=KNOWN_RATE, planner="auto", steps=10,
        seed=0, val_objects=0, size=True, camera="model", unknowns="unknowns", unknowns_root=None,
        score=OPEN_SET_SCORE, size_weights=SIZE_WEIGHTS):
    """The `open_set` entry of the model at `path` (see the module's docstring)."""
    if not size_weights or any(not (np.isfinite(w) and w >= 0) for w in size_weights):
        raise InputError(f"size_weights must be numbers >= 0, at least one, got {list(size_weights)}")
    if score not in OPEN_SET_SCORES:
        raise InputError(f"score must be one of {', '.join(OPEN_SET_SCORES)}, got {score!r}")
    model, classes, ckpt = checkpoint.load_model(path, dataset=dataset)
    if not 0 < known_rate <= 1:
        raise InputError(f"known_rate: the share of known objects to accept must lie in (0, 1], got {known_rate}")
    planner, fixed_path = node_planner(planner, model, ckpt)
    pixels = model.config.image_size
    renders = CameraConfig(pixels, pixels, radius=model.config.radius)
    # the episodes are the node's (its stop rule and price of travel): the answer is fitted for the node
    cfg = EvalConfig(checkpoint=str(path), dataset=dataset, root=root, split="val", steps=steps, seed=seed,
                     size=size, shared=False, entropy_threshold=ROBOT.entropy_threshold,
                     travel_cost=ROBOT.travel_cost)
    parts = open_splits(dataset, root, ("train", "val"), default_cache_dir())
    train, val = (Shapes(parts[s], renders) for s in ("train", "val"))
    if list(train.ds.classes) != classes:
        raise InputError(f"{path}: the checkpoint's classes {classes} are not the dataset's {train.ds.classes}")
    unknown = Shapes(open_dataset(unknowns, unknowns_root, "val", cache_dir=default_cache_dir()), renders)
    n = min(objects, len(train))
    if n < len(classes):
        raise InputError(f"objects = {objects}: the means need a training object of each of the {len(classes)} classes")
    fit_on = subset_with_every_class(train.labels, n, seed)
    ro, rec = episodes(planner, model, train, fit_on, cfg, fixed_path)
    means = prototype_means(rec["states"], ro.labels, model.config.num_classes)
    pick = {name: np.sort(np.random.default_rng(seed).permutation(len(s))[:val_objects or len(s)])
            for name, s in (("known", val), ("unknown", unknown))}
    through, sizes = {}, None
    if camera == "model":
        known = scored(planner, model, val, pick["known"], cfg, means, fixed_path, score)
        other = scored(planner, model, unknown, pick["unknown"], cfg, means, fixed_path, score)
    else:
        groups = (train.ds, fit_on), (val.ds, pick["known"]), (unknown.ds, pick["unknown"], unknowns, unknowns_root)
        means, known, other, through, sizes = through_camera(path, planner, dataset, root, camera, steps, seed,
                                                             size, *groups, means, score)
    floor = -np.inf if score == "energy_mean" else 1e-6  # an energy may be of any sign
    thresholds = plain = scores.held_thresholds(*known, cfg.entropy_threshold, known_rate, floor)
    weight = 0.0
    if score == "energy_mean" and any(size_weights) and size and sizes is not None and model.size_prior is not None:
        weight, through["size_weights"] = choose_size_weight(model.size_prior, known, other, sizes,
                                                             cfg.entropy_threshold, known_rate, size_weights)
        known = with_size(known, model.size_prior, sizes["known"], weight)
        other = with_size(other, model.size_prior, sizes["unknown"], weight)
        if weight:
            thresholds = scores.held_thresholds(*known, cfg.entropy_threshold, known_rate, floor)
    fitted_on = {"dataset": dataset, "planner": planner, "train_objects": int(n), "steps": int(steps),
                 "seed": int(seed), "size": bool(size), "known_rate": float(known_rate), "unknowns": unknowns,
                 "score": score,
                 "val_known": len(known[1]), "val_unknown": len(other[1]),
                 **val_figures(known, other, cfg.entropy_threshold, thresholds), "camera": camera,
                 **through}
    entry = {"score": score, "means": torch.from_numpy(means),
             "threshold": torch.from_numpy(thresholds), "fitted_on": fitted_on}
    if weight:  # with the size term; the thresholds without it for a recognizer not told the size
        entry |= {"size_weight": float(weight), "threshold_no_size": torch.from_numpy(plain)}
    return checked_open_set(entry, len(classes), model.config.state_size)


def val_figures(known, unknown, entropy_threshold, thresholds):
    """How per-step `thresholds` answer the val episodes under the recognizer's hold: the share of
    known and of unknown ones ended `unknown`, and the AUROC of their last running score; known,
    unknown: (probs, running score)."""
    return {"val_known_rejected": round(float(flagged(*known, entropy_threshold, thresholds).mean()), 4),
            "val_unknown_flagged": round(float(flagged(*unknown, entropy_threshold, thresholds).mean()), 4),
            "val_auroc": round(scores.auroc(known[1][:, -1], unknown[1][:, -1]), 4)}


def with_size(group, prior, sizes, weight):
    """(probs, running energy_mean + weight x the size prior's surprise at each episode's size)."""
    probs, running = group
    return probs, running + weight * prior.surprise(sizes)[:, None]


def choose_size_weight(prior, known, unknown, sizes, entropy_threshold, known_rate, weights=SIZE_WEIGHTS):
    """(weight, table): of `weights`, the weight of the size term (scores.size_term: weight x the
    size prior's surprise at each object's size, added to its running energy) under which the
    recognizer's hold, with thresholds fitted on the known val episodes at `known_rate`, ends the
    most val unknowns `unknown` (ties: the least weight); the table gives each weight's figures.
    known, unknown: (probs, running energy_mean) of the val episodes; sizes: {known, unknown: (N,)}."""
    table, best = {}, None
    for w in sorted(weights):
        k, u = with_size(known, prior, sizes["known"], w), with_size(unknown, prior, sizes["unknown"], w)
        thresholds = scores.held_thresholds(*k, entropy_threshold, known_rate, -np.inf)
        table[str(w)] = row = val_figures(k, u, entropy_threshold, thresholds)
        if best is None or row["val_unknown_flagged"] > table[str(best)]["val_unknown_flagged"]:
            best = w
    return float(best), table


def through_camera(path, planner, dataset, root, preset, steps, seed, size, train, val, unknown, rendered,
                   score=OPEN_SET_SCORE):
    """(means, known, unknown, notes, sizes) fitted on episodes through simulated camera `preset` as the
    node runs them (camera_episodes.py), each of `steps` images without a stop: the class means
    of the training episodes' states, or `rendered` (of the model's own renders) where those
    tell the val unknowns better (val AUROC of prototype_mean after `steps` views); known and
    unknown: (probs, running `score`) of the val episodes (prototype_mean against the chosen
    means); sizes: {known, unknown: (N,) each episode's object size in metres}."""
    from active_recognition.evaluation.camera_episodes import camera_runs, full_length, recording_core

    core = recording_core(path, planner, steps, seed, use_size=size)  # every step recorded
    runs = {}
    (uds, uobjects, uname, uroot) = unknown
    for group, (ds, objects), name, split, where in (("train", train, dataset, "train", root),
                                                     ("known", val, dataset, "val", root),
                                                     ("unknown", (uds, uobjects), uname, "val", uroot)):
        runs[group] = full_length(camera_runs(core, ds, name, split, objects, preset, seed, where, record=True),
                                  steps)
    labels = np.array([r.label for r in runs["train"][2]])
    candidates = {"camera": prototype_means(runs["train"][1], labels, len(train[0].classes)), "renders": rendered}
    scored_by = {k: {g: (runs[g][0], scores.prototype_mean(runs[g][1], m)) for g in ("known", "unknown")}
                 for k, m in candidates.items()}
    auroc = {k: scores.auroc(v["known"][1][:, -1], v["unknown"][1][:, -1]) for k, v in scored_by.items()}
    best = max(auroc, key=auroc.get)
    notes = {"means_from": best, "val_auroc_by_means": {k: round(v, 4) for k, v in auroc.items()},
             "train_objects_through_camera": len(runs["train"][2])}
    sizes = {g: np.array([r.size for r in runs[g][2]]) for g in ("known", "unknown")}
    if score == "energy_mean":  # each view's energy, as the recognizer took it
        return candidates[best], *(
            (runs[g][0], scores.running_mean(np.array([r.energies[:steps] for r in runs[g][2]])))
            for g in ("known", "unknown")), notes, sizes
    return candidates[best], scored_by[best]["known"], scored_by[best]["unknown"], notes, sizes


def store(path, entry, out=None):
    """Write the checkpoint at `path` with `entry` as its open_set to `out` (default: `path`
    itself), atomically, the entry checked first (nothing is written for a bad one); the result
    loads as any checkpoint (checkpoint.read checks it)."""
    model = checkpoint.load_model(path)[0]
    checked_open_set(entry, model.config.num_classes, model.config.state_size)
    checkpoint.update(path, out, open_set=entry)
    checkpoint.load_model(out or path)  # refuse now what the recognizer would refuse


def add_fit_flags(ap):
    """The fit's flags on `ap` (the CLI's open-set-fit subcommand, or main's own parser)."""
    add_flags(ap, EvalConfig, ["dataset", "root", "checkpoint", "seed", "steps", "size"], dataset={
        "choices": ("procedural", "modelnet"), "default": "modelnet", "help": "the known objects' dataset"})
    ap.add_argument("--objects", type=int, default=FIT_OBJECTS,
                    help=f"training objects the class means are fitted on (default {FIT_OBJECTS})")
    ap.add_argument("--val-objects", type=int, default=0,
                    help="seeded sample of the val objects, known and unknown, scored (0: all)")
    ap.add_argument("--known-rate", type=float, default=KNOWN_RATE,
                    help=f"share of known validation objects the threshold accepts (default {KNOWN_RATE})")
    ap.add_argument("--planner", default="auto", help=(
        "the planner of every episode (default auto: the recognizer's, the checkpoint's own)"))
    ap.add_argument("--camera", default="model", choices=("model", *PRESETS), help=(
        "the images the answer is fitted on: model = the model's own renders; a simulated camera "
        "preset = through it as the node runs (slower; realsense for a node on a real camera)"))
    ap.add_argument("--unknowns", default="unknowns", choices=tuple(OPEN_SET), help=(
        "the unknown val objects scored beside the known: generated (unknowns) or real meshes "
        "(real_unknowns, under --unknowns-root: tools/fetch_real_unknowns.py)"))
    ap.add_argument("--unknowns-root", default=None, help="real_unknowns' folder")
    ap.add_argument("--score", default=OPEN_SET_SCORE, choices=OPEN_SET_SCORES, help=(
        "the unknown score the thresholds are on: prototype_mean (the default: the state's cosine "
        "distance to the class means) or energy_mean (each view's -log sum exp of the logits, for "
        "a model trained with outliers)"))
    ap.add_argument("--size-weights", type=float, nargs="+", metavar="W", default=list(SIZE_WEIGHTS), help=(
        "energy_mean through a camera, with the objects' sizes: the weights of the size term "
        "(scores.size_term) tried on val, the one that flags the most val unknowns kept (default 0: no "
        f"size term; a grid: {' '.join(f'{w:g}' for w in SIZE_GRID)})"))
    ap.add_argument("--out", default=None, help="checkpoint to write (default: --checkpoint itself)")
    return ap


def run(args):
    """Fit and store as the flags say (InputError on bad input, before any work where it can)."""
    path = checkpoint.model_path(args.checkpoint, args.dataset)
    entry = fit(path, args.dataset, args.root, args.objects, args.known_rate, args.planner, args.steps,
                args.seed, args.val_objects, args.size, args.camera, args.unknowns, args.unknowns_root,
                args.score, args.size_weights)
    store(path, entry, args.out)
    steps = ", ".join(f"{t:.4f}" for t in entry["threshold"])
    print(f"{args.out or path}: open_set thresholds by views {steps}, size weight {entry.get('size_weight', 0.0):g}; "
          f"{entry['fitted_on']}", file=sys.stderr)


def main(argv=None):
    """`python -m active_recognition.unknown.fit`, as `active-recognition open-set-fit`."""
    ap = add_fit_flags(argparse.ArgumentParser(prog="python -m active_recognition.unknown.fit",
                                               description=__doc__.split("\n\n")[0]))
    args = ap.parse_args(argv)
    try:
        run(args)
    except InputError as e:
        ap.error(str(e))


def recorded_rollout(name, model, shapes, objects, starts, cfg, chunk=100, fixed_path=None):
    """evaluate.rollout of planner `name` with its logits and recurrent states recorded:
    (Rollout, record)."""
    from active_recognition.evaluation.evaluate import rollout
    from active_recognition.model.episode import reads_mirror

    rec = scores.Recorder(model)
    with torch.no_grad():
        ro = rollout(name, model, shapes, objects, starts, cfg, chunk=chunk, fixed_path=fixed_path, forward=rec)
    return ro, rec.record(ro.probs, chunk, cfg.steps, reads_mirror(model))


if __name__ == "__main__":
    main()
