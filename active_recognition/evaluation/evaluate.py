# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""The evaluation harness: every planner on the same objects, initial views and seeds.

Reports accuracy after 1..T views (each planner with its own recurrent classifier, and every
planner's views scored by one shared multi-view classifier), the paper's 3/6/9 table, information
gain per step, accuracy and views used with the entropy early stop; writes a per-object CSV, a
Markdown report and PNG plots.
"""
from __future__ import annotations

import warnings
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import torch

from active_recognition.argument_checks import (
    Check, InputError, SEED_MAX, input_file, nested, option, output_dir, validate,
)
from active_recognition.datasets import NAMES, SPLITS, default_cache_dir, open_dataset, open_splits
from active_recognition.datasets.shapes import Shapes
from active_recognition.evaluation.report import write_report
from active_recognition.model import checkpoint
from active_recognition.model.episode import Episode, EpisodeConfig, run
from active_recognition.model.network import READOUTS, READOUT_HELP
from active_recognition.model.policies import FIXED, PLANNERS, make_planner
from active_recognition.sensing.depth_layer import CameraConfig
from active_recognition.sensing.reach import ViewLimits, reach_of


@dataclass
class EvalConfig:
    checkpoint: str | None = option(None, kind=str, optional=True, length=(1, None),
                                    help="learned model (default: the dataset's shipped one)")
    reinforce_checkpoint: str | None = option(None, kind=str, optional=True, length=(1, None), help=(
        "model trained with 'train --policy reinforce' (for the reinforce planner)"))
    planner_checkpoints: dict = option({}, flag=False, help="planner -> its own model file")
    planners: tuple = option(("learned", "random", "straight", "oracle"), length=(1, None),
                             items=Check(str, choices=PLANNERS),
                             help=f"comma-separated, from {', '.join(PLANNERS)}")
    dataset: str = option("procedural", choices=NAMES, help="dataset layout")
    root: str | None = option(None, kind=str, optional=True, length=(1, None),
                              help="dataset root folder")
    split: str = option("test", choices=SPLITS, help=(
        "which split (val: a seeded tenth of each class of train, where choices are made; cross: "
        "a generated benchmark's held-out styles)"))
    objects: int = option(0, lo=0, help="seeded sample of objects (0: all)")
    starts: int = option(1, lo=1, hi=50, help="initial views per object (a seeded sample of the 50)")
    steps: int = option(10, lo=1, hi=100, help="views per episode")
    entropy_threshold: float = option(EpisodeConfig.entropy_threshold, lo=0, help=(
        "early-stop entropy (nats; the recognizer node's default is 0.5)"))
    travel_cost: float = option(EpisodeConfig.travel_cost, lo=0, hi=100, help=(
        "the imitation planner's price of travel: FC_view's log-score less this x radians (the "
        "recognizer node's default is 1)"))
    seed: int = option(0, lo=0, hi=SEED_MAX, help="objects, initial views, random planner")
    out: str = option("runs/eval", length=(1, None), help="report folder")
    shared: bool = option(True, help="also score every planner with the shared multi-view "
                                     "classifier (--no-shared: skip it)")
    judge: str | None = option(None, kind=str, optional=True, length=(1, None), help=(
        "a trained shared classifier to score with and pick the fixed path by, used as it is (e.g. "
        "docs/results/modelnet10/shared_classifier.pt); refused if trained on other shapes or "
        "through another camera (default: OUT/shared_classifier.pt, trained there first, minutes)"))
    keep_judge: bool = option(False, flag=False, help=(
        "judge is the user's file: used as it is, never trained over"))
    oracle_candidates: int = option(50, lo=1, hi=10_000, flag=False,
                                    help="candidate views the oracle planner weighs")
    trajectory_figures: int = option(3, lo=0, hi=100, flag=False,
                                     help="objects whose views are drawn")
    # the initial views are the paper's 50 that lie in the band, and every planner keeps to it
    limits: ViewLimits = nested(ViewLimits, flat=True)
    # a detector that knows the heading only roughly; the fixed path and the judge see it too
    yaw: float = option(0.0, lo=0, hi=180, help=(
        "degrees: turn every object by its own seeded yaw within +-this, its box re-fitted"))
    readout: str | None = option(None, kind=str, optional=True, choices=READOUTS,
                                 help=READOUT_HELP + "; default each model's own")
    size: bool = option(True, help=(
        "weigh what each object's size says of its class, where the model carries a size prior "
        "(modelnet10.pt, as the node's object_size); --no-size: from the images alone"))

    def __post_init__(self):
        validate(self)  # min above max is refused now (ViewLimits)
        twice = sorted({p for p in self.planners if self.planners.count(p) > 1})
        if twice:
            raise InputError(f"planners: {', '.join(twice)} named more than once")


@dataclass
class Rollout:
    planner: str
    objects: np.ndarray      # (N,) dataset indices
    labels: np.ndarray       # (N,)
    starts: np.ndarray       # (N,) index of the initial view among the 50
    views: np.ndarray        # (N, T + 1, 2)
    probs: np.ndarray        # (N, T, C)
    gain: np.ndarray         # (N, T) information gain per step
    stopped_at: np.ndarray   # (N,) step of the entropy stop (1-based)
    shared_probs: np.ndarray = field(default=None)  # (N, T, C) shared classifier on views[:t]
    path: np.ndarray = field(default=None)          # the fixed planner's path (k, 2)
    classes: list = field(default=None)             # the class names, in the order of the labels

    def accuracy(self, shared=False):
        probs = self.shared_probs if shared else self.probs
        return (probs.argmax(-1) == self.labels[:, None]).mean(0)          # (T,)

    def confusion(self, views=3, classes=None):
        """(C, C) counts of true class (rows) against the answer after `views` views."""
        c = classes or self.probs.shape[-1]
        pred = self.probs[:, views - 1].argmax(-1)
        return np.bincount(self.labels * c + pred, minlength=c * c).reshape(c, c)

    def early_stop(self):
        final = self.probs[np.arange(len(self.labels)), self.stopped_at - 1]
        return float((final.argmax(-1) == self.labels).mean()), float(self.stopped_at.mean())


def sample_episodes(n_objects, total, starts, seed, initial=50, pool=None):
    """(object indices, initial-view indices among `initial`) of the evaluation, the same for
    every planner; the objects are drawn from `pool` (None: all `total`)."""
    rng = np.random.default_rng(seed)
    pool = np.arange(total) if pool is None else np.asarray(pool)
    objects = pool if not n_objects else np.sort(pool[rng.permutation(len(pool))[:n_objects]])
    objects = np.repeat(objects, starts)
    return objects, rng.integers(0, initial, len(objects))


def halves(total, seed):
    """Seeded disjoint halves of a split's objects: (those the fixed path is picked on, those every
    planner is scored on), for the validation split, which does both when it picks the default
    planner: a path picked among 50 x 50 pairs on the objects it is scored on has an edge there."""
    order = np.random.default_rng(seed + 1).permutation(total)
    return np.sort(order[:total // 2]), np.sort(order[total // 2:])


def rollout(name, model, shapes, objects, starts, cfg: EvalConfig, chunk=100, fixed_path=None, forward=None):
    """Planner `name` on `objects` from `starts`, in chunks of `chunk` objects (`forward`: what runs
    the model a step, Episode.forward; open_set.Recorder keeps its logits and states)."""
    initial = cfg.limits.initial_views(50)
    parts = []
    for b in range(0, len(objects), chunk):
        idx = objects[b:b + chunk]
        cams = shapes.cameras(idx)
        planner = make_planner(name, cams, cfg.seed + b, cfg.oracle_candidates, model, fixed_path,
                               shapes.labels[idx])
        sizes = shapes.sizes(idx) if cfg.size and model.size_prior is not None else None
        ep = Episode(model, EpisodeConfig(cfg.steps, cfg.entropy_threshold, cfg.travel_cost), planner,
                     reach=reach_of(cfg.limits), forward=forward)
        with torch.no_grad():
            run(ep, cams, initial[starts[b:b + chunk]], cfg.steps,
                size=None if sizes is None else torch.from_numpy(sizes))
        parts.append((torch.stack(ep.views, 1).numpy(), torch.stack(ep.probs, 1).numpy(),
                      torch.stack(ep.info_gain, 1).numpy(), ep.stopped_at.numpy()))
    views, probs, gain, stopped = (np.concatenate(x) for x in zip(*parts))
    return Rollout(name, objects, shapes.labels[objects], starts, views, probs, gain, stopped,
                   classes=list(shapes.ds.classes))


def score_shared(net, shapes, ro: Rollout, chunk=50):
    """Shared classifier on every prefix views[:t] of each trajectory."""
    out = []
    with torch.no_grad():
        for b in range(0, len(ro.objects), chunk):
            cams = shapes.cameras(ro.objects[b:b + chunk])
            depth = np.stack([c.render(v[:-1]) for c, v in zip(cams, ro.views[b:b + chunk])])
            depth = torch.from_numpy(depth)                                  # (B, T, H, W)
            out.append(net.prefix_logits(depth).softmax(-1).numpy())
    ro.shared_probs = np.concatenate(out)


def checkpoint_split(path, cfg: EvalConfig, splits=None):
    """(model, classes, cfg's dataset split as the model's camera sees it, the checkpoint dict)
    for a checkpoint (None: the dataset's shipped one), refused unless its classes are the dataset's.
    `splits` keeps the splits (and their built cameras) for the next checkpoint with the same camera."""
    model, classes, ckpt = checkpoint.load_model(path, dataset=cfg.dataset)
    size, radius = model.config.image_size, model.config.radius
    splits = {} if splits is None else splits
    if (size, radius) not in splits:
        splits[size, radius] = Shapes(open_dataset(cfg.dataset, cfg.root, cfg.split,
                                                   cache_dir=default_cache_dir()),
                                      CameraConfig(size, size, radius=radius), cfg.yaw, cfg.seed)
    shapes = splits[size, radius]
    if list(shapes.ds.classes) != classes:
        raise InputError(f"{path or 'the shipped model'}: the checkpoint's classes {classes} are "
                         f"not the dataset's {shapes.ds.classes}")
    return model, classes, shapes, ckpt


def evaluate(cfg: EvalConfig, progress=True, runs=()):
    """Run every planner; write the report under cfg.out; return {planner: Rollout}. With
    `runs` (the learned and the reinforce run's metrics rows), the report holds the
    training-time comparison too."""
    paths = {**({"reinforce": cfg.reinforce_checkpoint} if cfg.reinforce_checkpoint else {}),
             **cfg.planner_checkpoints}
    if "reinforce" in cfg.planners and "reinforce" not in paths:
        raise InputError("the reinforce planner needs --reinforce-checkpoint (a model trained "
                         "with 'train --policy reinforce')")
    for name, path in paths.items():  # refuse a bad file now, not after an hour
        if name not in PLANNERS:
            raise InputError(f"planner checkpoint {name}={path}: no such planner (planners: "
                             f"{', '.join(PLANNERS)})")
        input_file(path, "checkpoint")
    if cfg.keep_judge:  # the user's judge: a missing file is refused now, not after the data loads
        if cfg.judge is None:
            raise InputError("keep_judge needs judge, the shared classifier's file")
        input_file(cfg.judge, "judge")
    out = output_dir(cfg.out, "out")
    model, classes, test, ckpt = checkpoint_split(cfg.checkpoint, cfg)
    follow = any(p in FIXED for p in cfg.planners)  # a planner needs the fixed path
    total = len(test.ds.require_objects())
    pool = picked_on = None  # val: the fixed path picked on one half, the planners scored on the other
    if cfg.split == "val" and follow:
        picked_on, pool = halves(total, cfg.seed)
    held = total if pool is None else len(pool)
    if cfg.objects > held:
        raise InputError(f"objects = {cfg.objects}, but the {cfg.dataset} {cfg.split} split holds "
                         f"{held}{' beside the fixed path' * (pool is not None)} (0 = all of them)")
    objects, starts = sample_episodes(cfg.objects, len(test), cfg.starts, cfg.seed,
                                      len(cfg.limits.initial_views(50)), pool)
    models = {name: checkpoint.load_model(path, classes)[0] for name, path in paths.items()}
    for m in (model, *models.values()) if cfg.readout else ():
        m.config.readout = cfg.readout
    if model.config.readout.endswith("+mirror") and not ckpt.get("config", {}).get("mirror"):
        warnings.warn(f"{cfg.checkpoint or 'the shipped model'}: readout {model.config.readout} "
                      f"reads each image's mirror image too, but the model was not trained with "
                      f"mirrored shapes (train --mirror): its answers from mirror images are "
                      f"untested")
    for name in ("imitation", "fixed+imitation"):  # FC_view needed: refuse now, not after the judge
        if name in cfg.planners:
            make_planner("imitation", model=models.get(name) or model)
    net = fixed = None
    if cfg.shared or follow:  # the neutral judge; it also finds the fixed path
        from active_recognition.evaluation.shared_classifier import load_or_train
        parts = open_splits(cfg.dataset, cfg.root, ("train", "val"), default_cache_dir())
        train, val = (Shapes(parts[s], test.camera, cfg.yaw, cfg.seed) for s in ("train", "val"))
        net = load_or_train(Path(cfg.judge or out / "shared_classifier.pt"), train, classes, cfg.keep_judge,
                            seed=cfg.seed, progress=progress, val=val)
        if follow:  # chosen on the validation split, which the judge did not learn from (it stops on it)
            from active_recognition.evaluation.view_sets import fixed_path
            fixed, val_acc = fixed_path(net, val, seed=cfg.seed, limits=cfg.limits,
                                        indices=picked_on, length=cfg.steps - 1)
            if progress:
                print(f"fixed path {np.round(fixed, 3).tolist()} (shared-classifier accuracy "
                      f"{val_acc:.3f} on the validation split)", flush=True)
    results = {}
    for name in cfg.planners:
        results[name] = rollout(name, models.get(name) or model, test, objects, starts, cfg,
                                fixed_path=fixed)
        results[name].path = fixed if name in FIXED else None
        if progress:
            print(f"{name}: accuracy after 1..{cfg.steps} views "
                  f"{np.round(results[name].accuracy(), 3).tolist()}", flush=True)
    if cfg.shared:
        for ro in results.values():
            score_shared(net, test, ro)
    s = summary(results)
    if runs:
        from active_recognition.training.run_metrics import training_time
        s["training_time"] = training_time(*runs, out / "training_time.png")
    write_report(results, s, classes, cfg, out, test)
    return results


def planner_checkpoints(items):
    """{planner: model file} from PLANNER=FILE strings (--planner-checkpoint)."""
    own = {}
    for item in items:
        name, sep, path = item.partition("=")
        if not sep or not name or not path:
            raise InputError(f"--planner-checkpoint {item!r}: expected PLANNER=FILE")
        if name in own:
            raise InputError(f"--planner-checkpoint: {name} is given twice")
        own[name] = path
    return own


# accuracies are kept to 6 decimals: at 4, a fraction such as 2631 / 2697 = 0.975528 was stored as
# 0.9755 and printed as 97.5 % (0.9755 is just below it in binary), where it is 97.6 %
DECIMALS = 6


def summary(results):
    """{'acc': {planner: {'3','6','9'}}, ...} as printed by benchmarks and written to JSON."""
    def at(ro, shared=False):
        acc = ro.accuracy(shared)
        return {str(k): round(float(acc[k - 1]), DECIMALS) for k in (3, 6, 9) if k <= len(acc)}
    s = {"acc": {n: at(ro) for n, ro in results.items()},
         "gain": {n: np.round(ro.gain.mean(0), 4).tolist() for n, ro in results.items()},
         "early_stop": {n: dict(zip(("accuracy", "mean_views"), (round(v, DECIMALS) for v in ro.early_stop())))
                        for n, ro in results.items()}}
    first = next(iter(results.values()))
    if first.classes is not None:  # every writer of a summary names the classes its tables use
        s["classes"] = first.classes
    three = first.probs.shape[1] >= 3  # episodes of 3 views or more
    if three:
        s["stderr_3"] = {n: standard_error(ro) for n, ro in results.items()}
    if three:  # accuracy per class after 3 views, in the order of the classes
        s["per_class_3"] = {n: [round(float(v), DECIMALS) for v in per_class(ro)] for n, ro in results.items()}
    paths = [ro.path for ro in results.values() if ro.path is not None]
    if paths:
        s["fixed_path"] = np.round(paths[0], 6).tolist()
    if all(ro.shared_probs is not None for ro in results.values()):
        s["acc_shared"] = {n: at(ro, True) for n, ro in results.items()}
        if three:
            s["stderr_3_shared"] = {n: standard_error(ro, True) for n, ro in results.items()}
    return s


def per_class(ro: Rollout, views=3):
    """Accuracy after `views` views of each class (NaN for a class with no episode)."""
    m = ro.confusion(views).astype(float)
    with np.errstate(invalid="ignore"):
        return np.diag(m) / m.sum(1)


def standard_error(ro: Rollout, shared=False, views=3):
    """Standard error of the accuracy after `views` views, with the starts of one object as one
    sample (they are not independent): std of the per-object accuracies / sqrt(objects)."""
    probs = ro.shared_probs if shared else ro.probs
    return round(object_standard_error(ro.objects, probs[:, views - 1].argmax(-1) == ro.labels), 4)


def object_standard_error(objects, correct):
    """Standard error of an accuracy over episodes of `objects` (N,) with `correct` (N,), the
    episodes of one object one sample: std of the per-object accuracies / sqrt(objects)."""
    ids, inverse = np.unique(objects, return_inverse=True)
    per_object = np.bincount(inverse, correct) / np.bincount(inverse)
    return float(per_object.std(ddof=1) / np.sqrt(len(ids))) if len(ids) > 1 else 0.0


def compare_runs(checkpoints, planners=("learned", "random", "straight"), starts=3, seed=0,
                 dataset="procedural", root=None, split="test", steps=10, objects=0):
    """Several trained models, each driving every planner on the same objects and initial views.

    `checkpoints` maps a label to a model file. Returns {label: {planner: accuracy after 1..steps
    views}}: random and straight are scored with that model's own classifier, so a row compares
    its view head with the baselines under one classifier (ablations, training variants).
    "learned" is the run's own view head: FC_view for a run trained with policy imitation.
    """
    cfg = EvalConfig(dataset=dataset, root=root, split=split, starts=starts, seed=seed, steps=steps,
                     objects=objects)
    out, splits = {}, {}
    for label, path in checkpoints.items():
        model, _, shapes, ckpt = checkpoint_split(path, cfg, splits)
        policy = ckpt.get("config", {}).get("policy")
        idx, st = sample_episodes(objects, len(shapes), starts, seed)
        out[label] = {n: np.round(rollout("imitation" if n == "learned" and policy == "imitation"
                                          else n, model, shapes, idx, st, cfg).accuracy(),
                                  4).tolist() for n in planners}
    return out
