# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""What each planner's episodes cost a robot, from a committed evaluation's per_object.csv (its
views, stops and answers, episode by episode): mean travel after 3 / 6 / 9 views; with the stop
rule, accuracy, views, travel and robot seconds (mean and p90); and accuracy within budgets of
robot seconds, an episode answering with what it has when its next view would overrun the
budget (or when its stop rule stops it first). The cost model (robot_time.RobotTime): a capture
per view, a settle per move, the great-circle travel at a steady angular speed. Every accuracy
with its standard error, the starts of one object one sample (evaluate.object_standard_error).

    python benchmarks/robot_seconds.py [--per-object CSV] [--add NAME=CSV ...] [--capture-s 0.1 ...]

`--add NAME=CSV` sets another evaluation's episodes beside them (its planners named NAME, or
NAME/planner where it holds several): e.g. the default planner with settings of its own.
`--budget-entropy T`: within a budget the added episodes stop at entropy T instead of where their
stop rule stopped them, as the node does with a time budget (controller.Timing's
budget_entropy_threshold); each step's entropy is log C less the sum of the recorded gains (C the
classes named in the CSVs' `true` column; gains kept to 4 decimals, so within 5e-4 nats).

Last line is JSON, also written to --out (default docs/results/modelnet10/robot_seconds.json)."""
import argparse
import csv
import math
from pathlib import Path

import numpy as np
from common import RESULTS, emit, one_line_errors

from active_recognition.argument_checks import InputError
from active_recognition.evaluation.evaluate import object_standard_error
from active_recognition.evaluation.report import write_json
from active_recognition.runtime.robot_time import RobotTime
from active_recognition.sensing.geometry import travel

BUDGETS = (4.0, 8.0, 12.0, 16.0, 24.0)
CUTS = (3, 6, 9)


def episodes(path):
    """{planner: [(object, true, stopped_at, early answer, answers (T,), views (T, 2), start,
    gains (T,) or None)]}."""
    out = {}
    with open(path, newline="") as f:
        for row in csv.DictReader(f):
            steps = sum(1 for k in row if k.startswith("view_") and row[k])
            views = np.array([[float(x) for x in row[f"view_{t}"].split(";")] for t in range(1, steps + 1)])
            answers = [row[f"pred_{t}"] for t in range(1, steps + 1)]
            gains = [row.get(f"gain_{t}") for t in range(1, steps + 1)]
            gains = np.array(gains, dtype=float) if all(gains) else None
            out.setdefault(row["planner"], []).append(
                (int(row["object"]), row["true"], int(row["stopped_at"]), row["early_stop_pred"], answers, views,
                 int(row["start"]), gains))
    if not out:
        raise InputError(f"{path}: no episodes")
    return out


def within(cost, views, stop, budget):
    """Views an episode takes within `budget` robot seconds (the first always), at most `stop`."""
    return taken_within(spent(cost, views), stop, budget)


def spent(cost, views):
    """(T,) robot seconds after each view of an episode's views (T, 2)."""
    return np.array([cost.seconds(views[:k]) for k in range(1, len(views) + 1)])


def taken_within(seconds, stop, budget):
    return int(min(max(np.searchsorted(seconds, budget, side="right"), 1), stop))


def entropy_stop(row, threshold, classes):
    """The view at which an episode stops at `threshold` nats: the first whose entropy (log
    `classes` less the gains so far) is below it, else its last."""
    if row[7] is None:
        raise InputError("--budget-entropy needs the per_object.csv's gain_t columns")
    below = np.flatnonzero(math.log(classes) - np.cumsum(row[7]) < threshold)
    return int(below[0]) + 1 if len(below) else len(row[7])


def planner_figures(cost, rows, budget_stops=None):
    """A planner's figures; within budgets its episodes stop at `budget_stops` (default: where
    their stop rule stopped them)."""
    objects = np.array([r[0] for r in rows])
    out = {"episodes": len(rows)}
    for k in CUTS:
        out[f"travel_deg_{k}"] = float(np.mean([math.degrees(travel(r[5][:k])) for r in rows]))
    stopped = [(r[1] == r[3], r[2], travel(r[5][:r[2]]), cost.seconds(r[5][:r[2]])) for r in rows]
    correct, views, moved, seconds = (np.array(x, dtype=float) for x in zip(*stopped))
    out.update({"stop_accuracy": float(correct.mean()), "stop_accuracy_se": object_standard_error(objects, correct),
                "stop_views": float(views.mean()), "stop_travel_deg": float(np.degrees(moved).mean()),
                "stop_seconds_mean": float(seconds.mean()), "stop_seconds_p90": float(np.percentile(seconds, 90))})
    cumulative = [spent(cost, r[5]) for r in rows]
    stops = stops_within(rows, budget_stops)
    for budget in BUDGETS:
        taken = [taken_within(c, stop, budget) for stop, c in zip(stops, cumulative)]
        right = np.array([r[1] == r[4][n - 1] for r, n in zip(rows, taken)], dtype=float)
        out[f"budget_{budget:g}_accuracy"] = float(right.mean())
        out[f"budget_{budget:g}_accuracy_se"] = object_standard_error(objects, right)
    return out


def budget_stops(threshold, runs, added):
    """{added planner: its episodes' stops within a budget, at `threshold` nats (--budget-entropy)}
    ({} without one); added: {planner: the CSV --add read it from}."""
    if threshold is None:
        return {}
    if not (0 <= threshold <= 10):  # NaN too
        raise InputError(f"--budget-entropy must be a number of nats in [0, 10], got {threshold}")
    if not added:
        raise InputError("--budget-entropy applies to the episodes --add names: add NAME=CSV")
    classes = len({r[1] for rows in runs.values() for r in rows})
    if classes < 2:
        raise InputError(f"--budget-entropy needs the number of classes, read from the CSVs' `true` "
                         f"column: it names {classes}")
    stops = {}
    for planner, path in added.items():
        try:
            stops[planner] = [entropy_stop(r, threshold, classes) for r in runs[planner]]
        except InputError as e:
            raise InputError(f"--add {path}: {e}") from None
    return stops


def stops_within(rows, budget_stops=None):
    """Where each episode of rows stops within a budget: at budget_stops where given, else where
    its stop rule stopped it."""
    return [r[2] for r in rows] if budget_stops is None else budget_stops


def robot_summary(path, cost=RobotTime()):
    """{planner: planner_figures} of an evaluation's per_object.csv (planners.py reports them)."""
    return {name: planner_figures(cost, rows) for name, rows in episodes(path).items()}


def paired(cost, rows, others, budget_stops=None):
    """{other planner: {figure: [mean difference, its standard error]}} of `rows` less each of
    `others` on the episodes they share (object and start), at the cuts and the budgets (rows'
    episodes stopping there at `budget_stops`, default their stop rule's); the starts of one
    object one sample."""
    stops = stops_within(rows, budget_stops)
    mine = {(r[0], r[6]): r[:2] + (stop,) + r[3:] for r, stop in zip(rows, stops)}
    out = {}
    for name, theirs in others.items():
        pairs = [(mine[(r[0], r[6])], r) for r in theirs if (r[0], r[6]) in mine]
        if not pairs:
            continue
        objects = np.array([a[0] for a, _ in pairs])
        figures = {f"cut_{k}": lambda r, k=k: r[4][min(k, len(r[4])) - 1] == r[1] for k in CUTS}
        figures.update({f"budget_{b:g}": lambda r, b=b: r[4][within(cost, r[5], r[2], b) - 1] == r[1]
                        for b in BUDGETS[:3]})
        out[name] = {}
        for figure, right in figures.items():
            diff = np.array([float(right(a)) - float(right(b)) for a, b in pairs])
            out[name][figure] = [round(float(diff.mean()), 4), round(object_standard_error(objects, diff), 4)]
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--per-object", default=str(RESULTS / "modelnet10" / "per_object.csv"),
                    help="an evaluation's per_object.csv (benchmarks/planners.py writes it)")
    ap.add_argument("--add", action="append", default=[], metavar="NAME=CSV",
                    help="another evaluation's per_object.csv, its planners named NAME (repeatable)")
    ap.add_argument("--capture-s", type=float, default=RobotTime.capture_s, help="robot seconds a capture")
    ap.add_argument("--settle-s", type=float, default=RobotTime.settle_s, help="robot seconds to settle a move")
    ap.add_argument("--rad-per-s", type=float, default=RobotTime.rad_per_s, help="angular speed, rad per second")
    ap.add_argument("--budget-entropy", type=float, default=None, metavar="NATS",
                    help="within a budget the added episodes stop at this entropy, as the node does with a "
                         "time budget (its budget_entropy_threshold); default: where their stop rule stopped")
    # --out by hand: a fixed default, written by every run (no partial-run guard)
    ap.add_argument("--out", default=str(RESULTS / "modelnet10" / "robot_seconds.json"), help="JSON of the figures")
    args = ap.parse_args()
    with one_line_errors(ap):
        cost = RobotTime(args.capture_s, args.settle_s, args.rad_per_s)
        if not Path(args.per_object).is_file():
            raise InputError(f"--per-object {args.per_object}: no such file")
        runs = episodes(args.per_object)
        committed_runs, added = dict(runs), {}  # added: {planner: the CSV it came from}
        for extra in args.add:
            name, sep, path = extra.partition("=")
            if not sep or not name or not Path(path).is_file():
                raise InputError(f"--add {extra}: NAME=CSV of an evaluation's per_object.csv expected")
            more = episodes(path)
            for p, rows in more.items():
                key = name if len(more) == 1 else f"{name}/{p}"
                runs[key], added[key] = rows, path
        stops = budget_stops(args.budget_entropy, runs, added)
    figures = {name: planner_figures(cost, rows, stops.get(name)) for name, rows in runs.items()}
    print(f"{'planner':<16} travel 3/6/9 (deg)   stop rule: accuracy, views, travel, seconds mean / p90   "
          + "  ".join(f"<= {b:g} s" for b in BUDGETS))
    for name, f in figures.items():
        print(f"{name:<16} {f['travel_deg_3']:4.0f} / {f['travel_deg_6']:4.0f} / {f['travel_deg_9']:4.0f}   "
              f"{100 * f['stop_accuracy']:5.1f} +- {100 * f['stop_accuracy_se']:.1f} %, {f['stop_views']:.2f}, "
              f"{f['stop_travel_deg']:4.0f} deg, {f['stop_seconds_mean']:5.1f} / {f['stop_seconds_p90']:5.1f} s   "
              + "  ".join(f"{100 * f[f'budget_{b:g}_accuracy']:5.1f} +- {100 * f[f'budget_{b:g}_accuracy_se']:.1f}"
                          for b in BUDGETS))
    out = {"per_object": str(Path(args.per_object).resolve().relative_to(RESULTS.parent.parent))
           if Path(args.per_object).resolve().is_relative_to(RESULTS.parent.parent) else args.per_object,
           "cost": {"capture_s": cost.capture_s, "settle_s": cost.settle_s, "rad_per_s": cost.rad_per_s},
           "budgets_s": list(BUDGETS), "added": args.add, "budget_entropy": args.budget_entropy, "planners": figures}
    for extra in args.add:  # each added planner against the committed ones, episode by episode
        name = extra.partition("=")[0]
        if name in runs:
            out.setdefault("paired", {})[name] = diff = paired(cost, runs[name], committed_runs, stops.get(name))
            print(f"{name} less each planner, paired (mean +- s.e., points): " + "; ".join(
                f"{p} " + ", ".join(f"{k} {100 * v[0]:+.1f} +- {100 * v[1]:.1f}" for k, v in d.items())
                for p, d in diff.items()))
    write_json(args.out, out)
    plot(cost, runs, Path(args.out).with_name("accuracy_vs_seconds.png"), stops)
    emit({"planners": len(figures)})


def plot(cost, runs, path, budget_stops=None):
    """Accuracy within each budget of robot seconds, a line per planner, to `path` (a planner's
    episodes stopping at budget_stops[planner] where given, else at their stop rule's)."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    budgets = np.arange(1.0, 40.5, 0.5)
    fig, ax = plt.subplots(figsize=(7, 4.5))
    for name, rows in runs.items():
        cumulative = [spent(cost, r[5]) for r in rows]
        stops = stops_within(rows, (budget_stops or {}).get(name))
        steps = [[taken_within(c, stop, b) for stop, c in zip(stops, cumulative)] for b in budgets]
        acc = [np.mean([r[1] == r[4][n - 1] for r, n in zip(rows, taken)]) for taken in steps]
        ax.plot(budgets, 100 * np.array(acc), label=name, linestyle="--" if name == "oracle" else "-")
    ax.set(xlabel="robot seconds (budget)", ylabel="accuracy (%)",
           title=f"answering before the next view would overrun the budget (capture {cost.capture_s:g} s, "
                 f"settle {cost.settle_s:g} s, {cost.rad_per_s:g} rad/s)")
    ax.title.set_fontsize(8)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


if __name__ == "__main__":
    main()
