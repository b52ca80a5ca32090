# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""One evaluation's report: its tables (Markdown, CSV, JSON) and plots (PNG)."""
from __future__ import annotations

import csv
import json
import math
from pathlib import Path

import numpy as np

from active_recognition.atomic_files import atomic_write, write_text
from active_recognition.sensing import geometry
from active_recognition.training.visualize import plt, save_figure

PAPER = {  # the paper's accuracy after 3 / 6 / 9 views, random initial view (Table)
    "ModelNet10": (87.7, 89.8, 91.2), "ModelNet40": (86.1, 88.7, 89.8),
    "ShapeNetCore55": (71.6, 74.5, 76.9)}
# the paper's Table 3 on ModelNet10: accuracy % after 3 / 6 / 9 views, random initial view
PAPER_MODELNET10 = {"3DShapeNets": (76.9, 81.8, 82.5), "MV-RNN": (86.4, 88.9, 89.5),
                    "Pairwise": (84.9, 87.7, 89.2), "Ours (the paper)": (87.7, 89.8, 91.2)}
PAPER_TRAINING_HOURS = {"end-to-end (ours in the paper)": 19.5, "MV-RNN (REINFORCE)": 66.0,
                        "3DShapeNets": 96.0}


def write_report(results, s, classes, cfg, out, shapes):
    """One evaluation's outputs in `out`: per_object.csv, summary.json (the summary `s`), the
    plots and report.md."""
    out = Path(out)
    write_csv(out / "per_object.csv", results, classes)
    write_json(out / "summary.json", s)
    plot_accuracy(results, out / "accuracy_vs_views.png")
    if next(iter(results.values())).probs.shape[1] >= 3:
        plot_confusion(results, classes, out / "confusion.png")
    plot_gain(results, out / "information_gain.png")
    plot_trajectories(results, shapes, out / "trajectories.png", cfg.trajectory_figures)
    markdown = render_markdown(results, s, cfg)
    write_text(out / "report.md", markdown)


def table(rows, header):
    lines = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    lines += ["| " + " | ".join(str(c) for c in r) + " |" for r in rows]
    return "\n".join(lines)


def at_369(acc):
    """Table cells of the accuracy (%) after 3, 6 and 9 views; "-" beyond the episode's length."""
    return [f"{100 * acc[k]:.1f}" if k in acc else "-" for k in ("3", "6", "9")]


def render_markdown(results, s, cfg):
    n = len(next(iter(results.values())).objects)
    parts = [f"Dataset `{cfg.dataset}` ({cfg.split} split), {n} episodes "
             f"({cfg.starts} initial view(s) per object, seed {cfg.seed}), {cfg.steps} views each. "
             "`oracle` is privileged: it renders every candidate view of the object.", "",
             "### Accuracy (%) after 3 / 6 / 9 views, each planner with its recurrent classifier", "",
             table([[k] + at_369(s["acc"][k]) for k in results],
                   ["planner", "3 views", "6 views", "9 views"])]
    if "acc_shared" in s:
        parts += ["", "### Accuracy (%) with one shared multi-view classifier (views compared, "
                  "not classifiers)", "",
                  table([[k] + at_369(s["acc_shared"][k]) for k in results],
                        ["planner", "3 views", "6 views", "9 views"])]
    steps = len(next(iter(s["gain"].values())))
    parts += ["", "### Accuracy (%) after 1..T views", "",
              table([[k] + [f"{100 * a:.1f}" for a in ro.accuracy()] for k, ro in results.items()],
                    ["planner"] + [str(t + 1) for t in range(steps)]),
              "", "### Information gain per step, H(p_{t-1}) - H(p_t) in nats (p_0 uniform)", "",
              table([[k] + [f"{g:.3f}" for g in v] for k, v in s["gain"].items()],
                    ["planner"] + [str(t + 1) for t in range(steps)]),
              "", f"### Early stop (entropy < {cfg.entropy_threshold} or {cfg.steps} views)", "",
              table([[k, f"{100 * v['accuracy']:.1f}", f"{v['mean_views']:.2f}"]
                     for k, v in s["early_stop"].items()], ["planner", "accuracy %", "mean views"]),
              "", "The paper (accuracy % after 3 / 6 / 9 views, random initial view): "
              + "; ".join(f"{k} {a} / {b} / {c}" for k, (a, b, c) in PAPER.items()) + ".",
              "", "![accuracy](accuracy_vs_views.png) ![gain](information_gain.png)",
              "", "![trajectories](trajectories.png)"]
    if "per_class_3" in s and "classes" in s:  # episodes of 3 views or more
        names = list(s["per_class_3"])
        parts += ["", "### Accuracy (%) of each class after 3 views", "",
                  table([[c] + ["-" if math.isnan(s["per_class_3"][n][i]) else f"{100 * s['per_class_3'][n][i]:.1f}"
                                for n in names] for i, c in enumerate(s["classes"])], ["class", *names]),
                  "", "![confusion after 3 views](confusion.png)"]
    return "\n".join(parts) + "\n"


def plot_accuracy(results, path):
    pyplot = plt()
    shared = all(ro.shared_probs is not None for ro in results.values())
    fig, axes = pyplot.subplots(1, 2 if shared else 1, figsize=(10 if shared else 5.5, 4), squeeze=False)
    for ax, use_shared in zip(axes[0], (False, True)):
        for name, ro in results.items():
            acc = ro.accuracy(use_shared)
            ax.plot(np.arange(1, len(acc) + 1), 100 * acc, marker="o", ms=3, label=name)
        ax.set_xlabel("views")
        ax.set_ylabel("accuracy %")
        ax.set_title("shared multi-view classifier" if use_shared else "own recurrent classifier")
        ax.grid(alpha=0.3)
        ax.legend()
    fig.tight_layout()
    save_figure(fig, path, dpi=110)
    pyplot.close(fig)


def plot_confusion(results, classes, path, views=3):
    """Each planner's confusion matrix after `views` views, rows normalised (true class)."""
    pyplot = plt()
    n = len(results)
    fig, axes = pyplot.subplots(1, n, figsize=(3.2 * n + 1, 3.6), squeeze=False)
    for ax, (name, ro) in zip(axes[0], results.items()):
        m = ro.confusion(views, len(classes)).astype(float)
        m /= np.maximum(m.sum(1, keepdims=True), 1)
        ax.imshow(m, vmin=0, vmax=1, cmap="Blues")
        ax.set_title(f"{name}: {100 * np.trace(ro.confusion(views, len(classes))) / len(ro.labels):.1f} %",
                     fontsize=8)
        ax.set_xticks(range(len(classes)), classes, rotation=90, fontsize=6)
        ax.set_yticks(range(len(classes)), classes if ax is axes[0][0] else [], fontsize=6)
        ax.set_xlabel(f"answer after {views} views", fontsize=7)
    fig.tight_layout()
    save_figure(fig, path, dpi=110)
    pyplot.close(fig)


def plot_gain(results, path):
    pyplot = plt()
    fig, ax = pyplot.subplots(figsize=(5.5, 4))
    for name, ro in results.items():
        g = ro.gain.mean(0)
        ax.plot(np.arange(1, len(g) + 1), g, marker="o", ms=3, label=name)
    ax.set_xlabel("step")
    ax.set_ylabel("information gain (nats)")
    ax.grid(alpha=0.3)
    ax.legend()
    fig.tight_layout()
    save_figure(fig, path, dpi=110)
    pyplot.close(fig)


def plot_trajectories(results, shapes, path, objects=3, views=6):
    """Depth images along each planner's trajectory for a few objects, and the paths on the sphere."""
    pyplot = plt()
    names = list(results)
    first = results[names[0]]
    views = min(views, first.probs.shape[1])
    picks = np.linspace(0, len(first.objects) - 1, max(1, objects)).astype(int)
    rows = len(picks) * len(names)
    fig = pyplot.figure(figsize=(1.5 * (views + 2), 1.5 * rows))
    for r, (i, name) in enumerate((i, n) for i in picks for n in names):
        ro = results[name]
        cam = shapes.cameras([ro.objects[i]])[0]
        depth = cam.render(ro.views[i, :views])
        for c in range(views):
            ax = fig.add_subplot(rows, views + 2, r * (views + 2) + c + 1)
            ax.imshow(depth[c], cmap="viridis", vmin=0, vmax=255)
            ax.set_axis_off()
            if c == 0:
                label = shapes.ds.classes[ro.labels[i]]
                ax.set_title(f"{name}: {label}", fontsize=7, loc="left")
        ax = fig.add_subplot(rows, views + 2, (r + 1) * (views + 2) - 1, projection="3d")
        p = geometry.camera_position(ro.views[i, :views, 0], ro.views[i, :views, 1])
        ax.plot(p[:, 0], p[:, 1], p[:, 2], "-o", ms=2)
        ax.scatter(*p[0], color="red", s=8)
        ax.set_xlim(-1, 1), ax.set_ylim(-1, 1), ax.set_zlim(-1, 1)
        ax.set_axis_off()
    fig.tight_layout()
    save_figure(fig, path, dpi=90)
    pyplot.close(fig)


def write_csv(path, results, classes):
    with atomic_write(path, newline="") as f:
        w = csv.writer(f)
        steps = next(iter(results.values())).probs.shape[1]
        w.writerow(["planner", "object", "true", "start", "stopped_at", "early_stop_pred"]
                   + [f"pred_{t + 1}" for t in range(steps)]
                   + [f"shared_pred_{t + 1}" for t in range(steps)]
                   + [f"gain_{t + 1}" for t in range(steps)]
                   + [f"view_{t + 1}" for t in range(steps)])
        for name, ro in results.items():
            for i in range(len(ro.objects)):
                preds = ro.probs[i].argmax(-1)
                shared = (ro.shared_probs[i].argmax(-1) if ro.shared_probs is not None
                          else [-1] * steps)
                w.writerow([name, int(ro.objects[i]), classes[ro.labels[i]], int(ro.starts[i]),
                            int(ro.stopped_at[i]), classes[preds[ro.stopped_at[i] - 1]]]
                           + [classes[p] for p in preds]
                           + [classes[p] if p >= 0 else "" for p in shared]
                           + [f"{g:.4f}" for g in ro.gain[i]]
                           + [f"{t:.4f};{p:.4f}" for t, p in ro.views[i, :-1]])


def write_json(path, data):
    write_text(path, json.dumps(data, indent=1))
