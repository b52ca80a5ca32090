# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""The size prior's weight and outlier chance, chosen on ModelNet10's validation split.

Fits the prior (size_prior.py) on the training split less validation, runs the model's planners
on every validation object (3 starts, 9 views) answering from the images alone, then weighs each
answer by p(size | class)^weight for every setting of the grid, and keeps the one with the best
mean accuracy after 3, 6 and 9 views over the planners. Writes the grid and the choice to
docs/results/modelnet10/size_prior.json; with --write, stores the chosen prior in the checkpoint
(atomically; train does the same at the end of every run, with size_prior.SizePrior's defaults).
Last line is JSON.

    python benchmarks/size_prior_weight.py --root ~/data/ModelNet10 [--write]
"""
import argparse
import itertools
from pathlib import Path

import numpy as np
import torch
from common import emit, one_line_errors, results_dir

from active_recognition.datasets import default_cache_dir, open_splits
from active_recognition.datasets.shapes import Shapes
from active_recognition.evaluation.evaluate import DECIMALS, EvalConfig, checkpoint_split, rollout, sample_episodes
from active_recognition.evaluation.report import write_json
from active_recognition.model import checkpoint
from active_recognition.model.size_prior import fit
from active_recognition.options.flags_and_parameters import add_flags

WEIGHTS = (0.25, 0.5, 0.75, 1.0)
OUTLIERS = (0.01, 0.05, 0.2)
VIEWS = (3, 6, 9)


def accuracy(probs, labels):
    return {str(k): round(float((probs[:, k - 1].argmax(-1) == labels).mean()), DECIMALS) for k in VIEWS}


def record_path(model):
    """Where the record of `model` goes: a shipped ModelNet10 model's is committed beside the
    tables that RESULTS reads (modelnet10.pt: size_prior.json, modelnet10_reinforce.pt:
    size_prior_reinforce.json); another model's goes beside its file."""
    model, shipped = Path(model).resolve(), Path(checkpoint.shipped("modelnet")).resolve()
    if model.parent == shipped.parent and model.stem.startswith(shipped.stem):
        return results_dir("modelnet") / f"size_prior{model.stem[len(shipped.stem):]}.json"
    return model.with_name(f"{model.stem}_size_prior.json")


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    add_flags(ap, EvalConfig, ["root", "checkpoint", "planners", "starts"], root={
        "required": True, "help": "ModelNet10 root folder"}, checkpoint={"help": "model file (default: modelnet10.pt)"},
        planners={"default": ("random", "straight", "imitation")}, starts={"default": 3})
    ap.add_argument("--write", action="store_true", help="store the chosen prior in the checkpoint")
    # --out by hand: its default follows --checkpoint (no partial-run guard)
    ap.add_argument("--out", default=None, help="JSON (default: docs/results/modelnet10/size_prior[_SUFFIX].json for "
                                                "the shipped modelnet10[_SUFFIX].pt, else "
                                                "CHECKPOINT_size_prior.json)")
    args = ap.parse_args()
    with one_line_errors(ap):  # a bad root or model file: one line, not a traceback
        run(args)


def run(args):
    path = checkpoint.model_path(args.checkpoint, "modelnet")
    cfg = EvalConfig(checkpoint=str(path), dataset="modelnet", root=args.root, split="val",
                     starts=args.starts, steps=max(VIEWS), size=False, shared=False)
    model, classes, val, ckpt = checkpoint_split(str(path), cfg)
    train = Shapes(open_splits("modelnet", args.root, ("train",), default_cache_dir())["train"], val.camera)
    sizes = train.sizes(range(len(train)))
    objects, starts = sample_episodes(0, len(val), args.starts, 0, len(cfg.limits.initial_views(50)))
    runs = {name: rollout(name, model, val, objects, starts, cfg) for name in args.planners}
    val_sizes = torch.from_numpy(val.sizes(objects))
    grid = {}
    for weight, outlier in [(0.0, OUTLIERS[0]), *itertools.product(WEIGHTS, OUTLIERS)]:
        prior = fit(sizes, train.labels, len(classes), weight, outlier)
        acc = {name: accuracy(np.stack([prior.apply(torch.from_numpy(ro.probs[:, t]), val_sizes).numpy()
                                        for t in range(ro.probs.shape[1])], 1), ro.labels)
               for name, ro in runs.items()}
        grid[f"weight {weight} outlier {outlier}"] = {
            "weight": weight, "outlier": outlier, "acc": acc,
            "mean": round(float(np.mean([a[str(k)] for a in acc.values() for k in VIEWS])), DECIMALS)}
    best = max(grid.values(), key=lambda g: g["mean"])
    record = {"split": "val", "objects": len(val), "starts": args.starts, "checkpoint": path.name,
              "train_objects": len(train), "grid": grid,
              "chosen": {"weight": best["weight"], "outlier": best["outlier"]}}
    write_json(Path(args.out or record_path(path)), record)
    if args.write:
        prior = fit(sizes, train.labels, len(classes), best["weight"], best["outlier"])
        checkpoint.save(path, {k: v for k, v in ckpt.items() if k != "format"} | {"size_prior": prior.to_dict()})
    emit({"chosen": record["chosen"], "images_alone": grid["weight 0.0 outlier 0.01"]["acc"],
          "with_size": best["acc"], "written": str(path) if args.write else None})


if __name__ == "__main__":
    main()
