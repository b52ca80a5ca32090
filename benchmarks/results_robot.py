# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""docs/RESULTS.md's sections on what a robot meets (results_page.py's builders for them): the
robot seconds of each planner's test episodes, the node through the simulated RealSense part by
part, and the unknown answer on real meshes of other classes; and the two helpers every builder
uses, load and pct."""
import json
from pathlib import Path

from active_recognition.evaluation.report import table


def load(path):
    """A committed JSON output, or None where it was not written."""
    path = Path(path)
    return json.loads(path.read_text()) if path.is_file() else None


def pct(x, spec=".1f"):
    return f"{100 * x:{spec}}"


def pm(value, se):
    return f"{pct(value)} ± {pct(se)}"


def robot_seconds(results):
    """What each planner's test episodes cost an arm (benchmarks/robot_seconds.py)."""
    d = load(results / "modelnet10" / "robot_seconds.json")
    if d is None:
        return None
    budgets = d["budgets_s"]
    rows = [[name, " / ".join(f"{f[f'travel_deg_{k}']:.0f}" for k in (3, 6, 9)),
             pm(f["stop_accuracy"], f["stop_accuracy_se"]), f"{f['stop_views']:.2f}",
             f"{f['stop_travel_deg']:.0f}", f"{f['stop_seconds_mean']:.1f} / {f['stop_seconds_p90']:.1f}"]
            + [pm(f[f"budget_{b:g}_accuracy"], f[f"budget_{b:g}_accuracy_se"]) for b in budgets]
            for name, f in d["planners"].items()]
    head = ["planner", "travel after 3 / 6 / 9 views (deg)", "stop rule: accuracy %", "views", "travel (deg)",
            "robot s mean / p90"] + [f"within {b:g} s %" for b in budgets]
    paired = [[f"{name} less {other}"] + [f"{100 * v[0]:+.1f} ± {100 * v[1]:.1f}" for v in figures.values()]
              for name, against in d.get("paired", {}).items() for other, figures in against.items()
              if other != "oracle"]
    keys = next(iter(next(iter(d["paired"].values())).values())) if d.get("paired") else []
    columns = ["episodes paired (points)"] + [k.replace("_", " ") + " s" * k.startswith("budget") for k in keys]
    return {"cost": ", ".join(f"{k} {v:g}" for k, v in d["cost"].items()), "table": table(rows, head),
            "paired": table(paired, columns) if paired else ""}


def camera_parts(results):
    """The node through the simulated RealSense, each part changed alone (benchmarks/camera_parts.py)."""
    d = load(results / "modelnet10" / "camera_parts.json")
    if d is None:
        return None
    rows = [[name, pm(r["accuracy"], r["accuracy_se"]), f"{100 * r['minus_defaults']:+.1f} ± "
             f"{100 * r['minus_defaults_se']:.1f}", pct(r["unknown"]), f"{r['views']:.2f}", f"{r['travel_deg']:.0f}",
             f"{r['robot_s']:.1f} / {r['robot_s_p90']:.1f}"] for name, r in d["rows"].items()]
    return {"objects": d["objects"], "episode": ", ".join(f"{k} {v:g}" for k, v in d["episode"].items()),
            "table": table(rows, ["node", "accuracy %", "less the defaults", "answered unknown %", "views",
                                  "travel (deg)", "robot s mean / p90"])}


def real_unknowns(results):
    """The unknown answer on real meshes of other classes, through the camera (open_set_camera.py)."""
    d = load(results / "modelnet10" / "open_set_camera_real.json")
    if d is None:
        return None
    near = d.get("near", {})
    plain = (load(results / "modelnet10" / "size_term.json") or {}).get("test_shipped_without_sizes")
    nosize = "not measured" if plain is None else (
        f"a known accuracy of {pct(plain['known_accuracy'])} %, {pct(plain['unknown_flagged'])} % of the unknown "
        f"objects answered `unknown` at {pct(plain['known_rejected'])} % of the known, AUROC {plain['auroc']:.3f}")
    return {"known": d["objects"]["known"], "unknown": d["objects"]["unknown"], "nosize": nosize,
            "flagged": pct(d["unknown_flagged"]), "rejected": pct(d["known_rejected"]),
            "accuracy": pct(d["known_accuracy"]), "auroc": f"{d['auroc']:.3f}",
            "score": d.get("score", "prototype_mean"),
            "near": near.get("objects", 0), "near_flagged": pct(near.get("unknown_flagged", 0.0)),
            "near_auroc": f"{near.get('auroc', float('nan')):.3f}"}
