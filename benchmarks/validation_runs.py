# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""Candidate models compared on a dataset's validation split (a seeded tenth of each class of its
training split), as a model or a setting is chosen: each model's own classifier, with its own
view heads and the fixed motions, after 3 / 6 / 9 views on the same objects and initial views.
Adds one run per model to the validation JSON (default docs/results/modelnet10/validation.json
for modelnet, docs/results/validation.json for procedural), keeping the runs already there. Last line is JSON."""
import argparse
import json
import tempfile
from pathlib import Path

from common import emit, one_line_errors, results_dir

from active_recognition.evaluation.evaluate import EvalConfig, evaluate, summary
from active_recognition.evaluation.report import write_json
from active_recognition.options.flags_and_parameters import add_flags
from active_recognition.sensing.reach import ViewLimits


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("models", nargs="+", metavar="NAME=FILE", help="a run's name and its model file")
    add_flags(ap, EvalConfig, ["dataset", "root", "objects", "starts", "planners", "readout", "min_elevation",
                               "yaw"], dataset={"default": "modelnet"}, objects={"default": 352},
              starts={"default": 2}, planners={"default": ("learned", "random", "straight", "imitation")})
    # --out by hand: a JSON added to, its default the dataset's (no partial-run guard)
    ap.add_argument("--out", default=None, help="JSON to add to (default: the dataset's "
                                                "docs/results/<folder>/validation.json)")
    args = ap.parse_args()
    with one_line_errors(ap):
        out = Path(args.out or results_dir(args.dataset) / "validation.json")
        record = json.loads(out.read_text()) if out.is_file() else {}
        setting = {"objects": args.objects, "starts": args.starts, "min_elevation": args.min_elevation,
                   "yaw": args.yaw}
        held = {k: record.get(k, {"min_elevation": -90.0, "yaw": 0.0}.get(k)) for k in setting}
        if record and held != setting:
            ap.error(f"{out} holds runs with {held}: compare on the same settings (--objects, "
                     f"--starts, --min-elevation, --yaw), or write to another --out")
        record.update(split="val", **setting)
        runs = record.setdefault("runs", {})
        for item in args.models:
            name, sep, path = item.partition("=")
            if not sep:
                ap.error(f"{item!r}: expected NAME=FILE")
            with tempfile.TemporaryDirectory() as tmp:
                s = summary(evaluate(EvalConfig(
                    checkpoint=path, planners=args.planners, dataset=args.dataset,
                    root=args.root, split="val", objects=args.objects, starts=args.starts, out=tmp,
                    shared=False, trajectory_figures=0, readout=args.readout,
                    limits=ViewLimits(args.min_elevation), yaw=args.yaw)))
            runs[name] = {"acc": s["acc"], "stderr_3": s["stderr_3"], "readout": args.readout or "own"}
            print(name, {k: v["3"] for k, v in s["acc"].items()})
        write_json(out, record)
        emit({"runs": {k: v["acc"] for k, v in runs.items()}})


if __name__ == "__main__":
    main()
