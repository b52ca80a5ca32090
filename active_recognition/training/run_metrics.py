# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""A training run's metrics: the per-epoch validation figures (evaluate_accuracy), the CSV that
train writes them to, read back and compared.

training_time puts two runs' joint stages side by side on the wall clock (the paper's claim that
end-to-end training reaches REINFORCE's accuracy in less time).
"""
from __future__ import annotations

import csv
import io
from pathlib import Path

import numpy as np
import torch

from active_recognition.argument_checks import InputError, read_text
from active_recognition.atomic_files import atomic_write
from active_recognition.model.episode import Episode, EpisodeConfig, run
from active_recognition.sensing.reach import ViewLimits, reach_of
from active_recognition.training.visualize import plt, save_figure


def write_metrics(path, rows):
    """Rewrite the metrics CSV atomically."""
    keys = list(dict.fromkeys(k for r in rows for k in r))
    with atomic_write(path, newline="") as f:
        w = csv.DictWriter(f, keys)
        w.writeheader()
        w.writerows(rows)


def read_metrics(path):
    if not Path(path).is_file():
        return []
    with open(path) as f:
        return list(csv.DictReader(f))


def scored(rows, column="acc_3"):
    """The joint-stage rows that hold a figure for `column` (a run with eval_every > 1 scores
    only every few epochs; the others are blank)."""
    return [r for r in rows if r["stage"] == "joint" and r.get(column) not in (None, "")]


def time_to_reach(rows, target, column="acc_3"):
    """Joint-stage wall-clock seconds at which `column` first reaches `target` (None if never)."""
    joint = scored(rows, column)
    if not joint:
        return None
    t0 = time_offset(rows)
    for r in joint:
        if float(r[column]) >= target:
            return float(r["wall_s"]) - t0
    return None


def time_offset(rows):
    """Wall-clock at the start of the joint stage (end of pre-training, if in the same run)."""
    pre = [float(r["wall_s"]) for r in rows if r["stage"] == "pretrain"]
    return max(pre) if pre else 0.0


def load_run_metrics(path, column="acc_3"):
    """The rows of a run's metrics.csv, for training_time; InputError naming the file unless every
    row has a number for wall_s and some joint-stage rows one for `column` too (the others blank:
    epochs the run did not score)."""
    rows = list(csv.DictReader(io.StringIO(read_text(path, "metrics"))))
    try:
        joint = scored(rows, column)
        ok = joint and all(np.isfinite([float(r["wall_s"]) for r in rows]
                                       + [float(r[column]) for r in joint]))
    except (KeyError, TypeError, ValueError):
        ok = False
    if not ok:
        raise InputError(f"metrics {path}: not a training run's metrics.csv with joint-stage rows "
                         f"of wall_s and {column} (train with --eval-shapes > 0)")
    return rows


def load_run_pair(learned, reinforce, column="acc_3"):
    """Both runs' metrics rows for training_time (load_run_metrics), or () when neither is given;
    InputError when only one is."""
    given = [m for m in (learned, reinforce) if m is not None]
    if len(given) == 1:
        raise InputError("--learned-metrics and --reinforce-metrics go together (the training-time "
                         "comparison needs both runs)")
    return tuple(load_run_metrics(m, column) for m in given)


def training_time(learned_rows, reinforce_rows, path=None, column="acc_3"):
    """Accuracy vs joint-stage wall-clock for both; the time ratio to reinforce's best accuracy."""
    best = max(float(r[column]) for r in scored(reinforce_rows, column))
    t_learned, t_rf = time_to_reach(learned_rows, best, column), time_to_reach(reinforce_rows, best, column)
    ratio = None if t_learned is None or not t_rf else t_learned / t_rf
    best_learned = max(float(r[column]) for r in scored(learned_rows, column))
    reverse = time_to_reach(reinforce_rows, best_learned, column)
    if path is not None:
        pyplot = plt()
        fig, ax = pyplot.subplots(figsize=(5.5, 4))
        for name, rows in (("learned (end to end)", learned_rows), ("reinforce", reinforce_rows)):
            t0 = time_offset(rows)
            joint = scored(rows, column)
            ax.plot([(float(r["wall_s"]) - t0) / 60 for r in joint],
                    [100 * float(r[column]) for r in joint], marker="o", ms=3, label=name)
        ax.axhline(100 * best, color="grey", lw=0.8, ls="--")
        ax.set_xlabel("joint-training wall-clock (min)")
        ax.set_ylabel(f"test accuracy % ({column.replace('acc_', '')} views)")
        ax.grid(alpha=0.3)
        ax.legend()
        fig.tight_layout()
        save_figure(fig, path, dpi=110)
        pyplot.close(fig)
    return {"reinforce_best": best, "learned_s": t_learned, "reinforce_s": t_rf, "ratio": ratio,
            "learned_best": best_learned, "reinforce_s_to_learned_best": reverse,
            "learned_s_to_learned_best": time_to_reach(learned_rows, best_learned, column)}


def evaluate_accuracy(model, shapes, n, steps=(1, 3, 10), seed=0, planner=None, limits=None):
    """Accuracy after 1, 3, 10 views from fixed initial views on a seeded sample of n shapes,
    with the model's own view head (or `planner`), within `limits` (None: the whole sphere)."""
    if n <= 0 or not len(shapes):
        return {}
    rng = np.random.default_rng(seed)
    idx = np.sort(rng.permutation(len(shapes))[:n])  # a fixed, seeded subset of every class
    starts = (limits or ViewLimits()).initial_views(50)
    views = starts[rng.integers(0, len(starts), len(idx))]
    was = model.training
    model.eval()
    with torch.no_grad():
        out = run(Episode(model, EpisodeConfig(max_views=max(steps)), planner, reach=reach_of(limits)),
                  shapes.cameras(idx), views)
    model.train(was)
    y = torch.as_tensor(shapes.labels[idx], device=out[0].probs.device)
    return {f"acc_{k}": round((out[k - 1].probs.argmax(1) == y).float().mean().item(), 4) for k in steps}


def own_planner(model, policy):
    """The planner a run trains: FC_view for imitation, else the model's FC_loc (None)."""
    if policy == "imitation" and model.config.candidates:
        from active_recognition.model.policies import ImitationPlanner
        return ImitationPlanner(model)
    return None
