# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""Fit a model's `unknown` answer and store it in its checkpoint (the key `open_set`).

The score is open_set's `prototype_mean`: the running mean, over the views an episode has taken,
of 1 - the largest cosine similarity of the step's recurrent state to a class mean of that step.
The per-step class means (steps, classes, state size) are fitted on the states of episodes of
--objects training objects (the training split less val, each class in the sample), each run by
--planner (default imitation, the shipped model's own) from a seeded initial view, from the
images alone. The threshold is the one that accepts --known-rate of the known validation objects
at the end the recognizer gives their episodes (hold_unknown: a confident answer waits while the
score is above the threshold; open_set.held_scores) (the dataset's val split): the
default 0.97 rejects about 3 % of them, a margin below the 5 % the test split may lose. The
unknowns' val styles (datasets/unknowns.py) are scored beside them and their share flagged kept
in `fitted_on`; their test styles are never read. The checkpoint is rewritten atomically.

    python -m active_recognition.open_set_fit --checkpoint PATH --dataset modelnet --root DIR
        [--objects 600] [--known-rate 0.97] [--out PATH]
"""
from __future__ import annotations

import argparse
import sys

import numpy as np
import torch

from . import checkpoint, open_set
from .datasets import default_cache_dir, open_dataset, open_splits, subset_with_every_class
from .datasets.shapes import Shapes
from .depth_layer import CameraConfig
from .evaluate import EvalConfig
from .options import add_flags
from .validation import InputError

FIT_OBJECTS = 600  # training objects whose states the means are fitted on
KNOWN_RATE = 0.97


def episodes(planner, model, shapes, objects, cfg):
    """(Rollout, record of logits and states) of one episode per object, each from a seeded start."""
    starts = np.random.default_rng(cfg.seed).integers(0, len(cfg.limits.initial_views(50)), len(objects))
    return open_set.recorded_rollout(planner, model, shapes, np.asarray(objects), starts, cfg)


def prototype_means(states, labels, num_classes):
    """Per-step class means (T, C, S) float32 of states (N, T, S) with labels (N,)."""
    states, labels = np.asarray(states), np.asarray(labels)
    missing = sorted(set(range(num_classes)) - set(labels.tolist()))
    if missing:
        raise InputError(f"open_set means: no training state of class(es) {missing}")
    return np.stack([states[labels == c].mean(0) for c in range(num_classes)], 1).astype(np.float32)


def fit_means(planner, model, shapes, objects, cfg):
    """The per-step class means (T, C, S) of the states of `objects` of `shapes` (training
    objects), in episodes of `planner`."""
    ro, rec = episodes(planner, model, shapes, objects, cfg)
    return prototype_means(rec["states"], ro.labels, model.config.num_classes)


def end_scores(planner, model, shapes, objects, cfg, means):
    """(N,) prototype_mean against `means` where each object's episode would end accepted under
    the recognizer's hold (open_set.held_scores: it keeps looking while the object looks unknown)."""
    ro, rec = episodes(planner, model, shapes, objects, cfg)
    running = open_set.running_mean(open_set.prototype_steps(rec["states"], means))
    return open_set.held_scores(ro.probs, running, cfg.entropy_threshold)


def fit(path, dataset, root=None, objects=FIT_OBJECTS, known_rate=KNOWN_RATE, planner="imitation", steps=10,
        seed=0, val_objects=0):
    """The `open_set` entry of the model at `path` (see the module's docstring)."""
    model, classes, _ = checkpoint.load_model(path, dataset=dataset)
    if not 0 < known_rate <= 1:
        raise InputError(f"known_rate: the share of known objects to accept must lie in (0, 1], got {known_rate}")
    size, radius = model.config.image_size, model.config.radius
    camera = CameraConfig(size, size, radius=radius)
    cfg = EvalConfig(checkpoint=str(path), dataset=dataset, root=root, split="val", steps=steps, seed=seed,
                     size=False, shared=False)
    parts = open_splits(dataset, root, ("train", "val"), default_cache_dir())
    train, val = (Shapes(parts[s], camera) for s in ("train", "val"))
    if list(train.ds.classes) != classes:
        raise InputError(f"{path}: the checkpoint's classes {classes} are not the dataset's {train.ds.classes}")
    unknown = Shapes(open_dataset("unknowns", split="val", cache_dir=default_cache_dir()), camera)
    n = min(objects, len(train))
    if n < len(classes):
        raise InputError(f"objects = {objects}: the means need a training object of each of the {len(classes)} classes")
    means = fit_means(planner, model, train, subset_with_every_class(train.labels, n, seed), cfg)
    pick = {name: np.sort(np.random.default_rng(seed).permutation(len(s))[:val_objects or len(s)])
            for name, s in (("known", val), ("unknown", unknown))}
    known = end_scores(planner, model, val, pick["known"], cfg, means)
    other = end_scores(planner, model, unknown, pick["unknown"], cfg, means)
    threshold = open_set.threshold_at(known, known_rate)
    fitted_on = {"dataset": dataset, "planner": planner, "train_objects": int(n), "steps": int(steps),
                 "seed": int(seed), "size": False, "known_rate": float(known_rate),
                 "val_known": len(known), "val_unknown": len(other),
                 "val_known_rejected": round(float((known > threshold).mean()), 4),
                 "val_unknown_flagged": round(float((other > threshold).mean()), 4),
                 "val_auroc": round(open_set.auroc(known, other), 4)}
    entry = {"score": checkpoint.OPEN_SET_SCORE, "means": torch.from_numpy(means), "threshold": threshold,
             "fitted_on": fitted_on}
    return checkpoint.checked_open_set(entry, len(classes), model.config.state_size)


def store(path, entry, out=None):
    """Write the checkpoint at `path` with `entry` as its open_set to `out` (default: `path`
    itself), atomically; the result loads as any checkpoint (checkpoint.read checks it)."""
    ckpt = checkpoint.read(path)
    ckpt.pop("format")
    checkpoint.save(out or path, {**ckpt, "open_set": entry})
    checkpoint.load_model(out or path)  # refuse now what the recognizer would refuse


def main(argv=None):
    ap = argparse.ArgumentParser(prog="python -m active_recognition.open_set_fit",
                                 description=__doc__.split("\n\n")[0])
    add_flags(ap, EvalConfig, ["dataset", "root", "checkpoint", "seed", "steps"], dataset={
        "choices": ("procedural", "modelnet"), "default": "modelnet", "help": "the known objects' dataset"})
    ap.add_argument("--objects", type=int, default=FIT_OBJECTS,
                    help=f"training objects the class means are fitted on (default {FIT_OBJECTS})")
    ap.add_argument("--val-objects", type=int, default=0,
                    help="seeded sample of the val objects, known and unknown, scored (0: all)")
    ap.add_argument("--known-rate", type=float, default=KNOWN_RATE,
                    help=f"share of known validation objects the threshold accepts (default {KNOWN_RATE})")
    ap.add_argument("--planner", default="imitation", help="the planner of every episode (default imitation)")
    ap.add_argument("--out", default=None, help="checkpoint to write (default: --checkpoint itself)")
    args = ap.parse_args(argv)
    try:
        path = checkpoint.model_path(args.checkpoint, args.dataset)
        entry = fit(path, args.dataset, args.root, args.objects, args.known_rate, args.planner, args.steps,
                    args.seed, args.val_objects)
        store(path, entry, args.out)
    except InputError as e:
        ap.error(str(e))
    print(f"{args.out or path}: open_set threshold {entry['threshold']:.4f}, {entry['fitted_on']}", file=sys.stderr)


if __name__ == "__main__":
    main()
