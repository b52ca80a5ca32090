# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""Trained runs side by side: each run's view head against random and straight views, scored by
that run's own classifier on the whole procedural test split (3 seeded initial views per object).

Two studies feed docs/RESULTS.md:
  ablations  -- the presets config/ablation_*.yaml (hidden size, radius), accuracy at 5 views;
  view_head  -- joint-stage variants from one pre-trained classifier (step bound, initial step,
                step weighting, REINFORCE), accuracy at 3 views;
  twins_candidates -- the candidate planners on the twins benchmark (end to end, its fixes,
                REINFORCE, the hybrid, imitation), each with its own view head (FC_view for
                imitation), accuracy at 3 views.
Writes docs/results/<study>.json and re-renders docs/RESULTS.md. Last line is JSON.
"""
import argparse
from pathlib import Path

from common import add_common_flags, emit
from results_page import write_results_page

from active_recognition.evaluation.evaluate import compare_runs
from active_recognition.evaluation.report import write_json

ROOT = Path(__file__).resolve().parents[1]
VIEWS = {"ablations": 5, "view_head": 3, "twins_candidates": 3}
DATASET = {"twins_candidates": "twins"}  # the others are procedural studies


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawTextHelpFormatter)
    ap.add_argument("study", choices=sorted(VIEWS))
    ap.add_argument("runs", nargs="+", metavar="LABEL=RUN_DIR",
                    help="a label and a run folder holding final.pt, e.g. hidden_64=runs/ablation_hidden_64")
    add_common_flags(ap, "starts", starts=3, starts_help="seeded initial views per test object")
    ap.add_argument("--out", default=str(ROOT / "docs/results"))  # by hand: a folder, not a JSON file
    args = ap.parse_args()
    runs = {}
    for item in args.runs:
        label, sep, folder = item.partition("=")
        path = Path(folder) / "final.pt"
        if not sep or not label:
            ap.error(f"{item!r}: expected LABEL=RUN_DIR")
        if not path.is_file():
            ap.error(f"{path}: no such checkpoint (train the run first)")
        runs[label] = str(path)
    acc = compare_runs(runs, starts=args.starts, dataset=DATASET.get(args.study, "procedural"))
    k = VIEWS[args.study]
    data = {"views": k, "starts": args.starts, "acc": acc}
    write_json(Path(args.out) / f"{args.study}.json", data)
    if (Path(args.out) / "summary.json").is_file():
        write_results_page(ROOT / "docs/RESULTS.md", args.out)
    emit({"views": k, "acc": {r: {p: v[k - 1] for p, v in a.items()} for r, a in acc.items()}})


if __name__ == "__main__":
    main()
