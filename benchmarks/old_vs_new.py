# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""The shipped procedural model before and after the furniture-like generator (#12), side by
side on the old generator's test split and on the new one's test and cross splits, so that
nobody is surprised: accuracy after 3 views with the learned and the straight planner, on the
same seeded objects and starts. The old generator is read from git (commit OLD), the old model
from OLD_MODEL (default: the checkpoint at commit OLD). Last line: JSON."""
import argparse
import importlib.util
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np
import torch
from common import emit, one_line_errors

from active_recognition.datasets import default_cache_dir, open_dataset
from active_recognition.datasets.shapes import Shapes
from active_recognition.evaluation.evaluate import DECIMALS
from active_recognition.evaluation.report import write_json
from active_recognition.model import checkpoint
from active_recognition.model.episode import Episode, EpisodeConfig, run
from active_recognition.model.policies import make_planner
from active_recognition.sensing import geometry
from active_recognition.sensing.depth_layer import CameraConfig

ROOT = Path(__file__).resolve().parents[1]
OLD = "ac4cc15"  # the last commit with the box-and-cylinder generator and its shipped model


def git_show(commit, path):
    return subprocess.run(["git", "-C", str(ROOT), "show", f"{commit}:{path}"], check=True,
                          capture_output=True).stdout


def old_test_split(commit):
    """The old generator's test split (500 objects), built from its source in git."""
    src = git_show(commit, "active_recognition/datasets/procedural.py").decode()
    src = src.replace("from ..meshes import normalise", "from active_recognition.sensing.meshes import normalise")
    src = src.replace("from .base import", "from active_recognition.datasets.base import")
    spec = importlib.util.spec_from_loader("old_procedural", loader=None)
    mod = importlib.util.module_from_spec(spec)
    exec(compile(src, "old_procedural.py", "exec"), mod.__dict__)
    return mod.generated("procedural-old", mod.CLASSES, mod.make_shape, 1, "test",
                         default_cache_dir())


def accuracy(model, shapes, idx, views, planner):
    cams = shapes.cameras(idx)
    plan = None if planner == "learned" else make_planner(planner, cams, seed=0)
    with torch.no_grad():
        out = run(Episode(model, EpisodeConfig(3), plan), cams, views, 3)
    return (out[-1].probs.argmax(1) == torch.as_tensor(shapes.labels[idx])).float().mean().item()


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawTextHelpFormatter)
    ap.add_argument("--objects", type=int, default=500, help="seeded objects per split")
    ap.add_argument("--old-model", default=None, help="the old model file (default: from git)")
    ap.add_argument("--model", action="append", default=[], metavar="NAME=FILE",
                    help="another model to compare, e.g. canonical=runs/ship_canonical/final.pt")
    # --out by hand: a fixed default, written by every run (no partial-run guard)
    ap.add_argument("--out", default=str(ROOT / "docs/results/old_vs_new.json"))
    args = ap.parse_args()
    with one_line_errors(ap):
        old_path = args.old_model
        if old_path is None:
            tmp = tempfile.NamedTemporaryFile(suffix=".pt", delete=False)
            tmp.write(git_show(OLD, "active_recognition/checkpoints/procedural.pt"))
            tmp.close()
            old_path = tmp.name
        models = {"old": checkpoint.load_model(old_path)[0], "new": checkpoint.load_model()[0]}
        if args.old_model is None:
            Path(old_path).unlink()  # the copy from git, read
        for item in args.model:
            name, sep, path = item.partition("=")
            if not sep or not name:
                ap.error(f"--model {item!r}: expected NAME=FILE")
            models[name] = checkpoint.load_model(path)[0]
        data = {"old test": old_test_split(OLD)}
        for s in ("test", "cross"):
            data[f"new {s}"] = open_dataset("procedural", split=s, cache_dir=default_cache_dir())
        result = {}
        for split, ds in data.items():
            rng = np.random.default_rng(0)
            idx = np.sort(rng.permutation(len(ds))[:args.objects])
            views = geometry.fibonacci_views(50)[rng.integers(0, 50, len(idx))]
            seen = {}  # each model through its own camera; models with the same camera share one
            for name, model in models.items():
                size, radius = model.config.image_size, model.config.radius
                if (size, radius) not in seen:
                    seen[size, radius] = Shapes(ds, CameraConfig(size, size, radius=radius))
                shapes = seen[size, radius]
                for planner in ("learned", "straight"):
                    acc = accuracy(model, shapes, idx, views, planner)
                    result[f"{name} model, {split}, {planner}"] = round(acc, DECIMALS)
                    print(f"{name} model on {split:<10} {planner:<9} acc@3 {acc:.3f}", file=sys.stderr)
        write_json(Path(args.out), result)
        emit(result)


if __name__ == "__main__":
    main()
