"""Planners compared on the procedural test split: learned (the shipped model), random, straight,
reinforce (a REINFORCE-trained model from the same pre-trained classifier) and oracle; and the
wall-clock for `learned` to reach the best accuracy `reinforce` reaches, over reinforce's time.
Writes the report under docs/results/ and docs/RESULTS.md. Last line is JSON."""
import argparse
import json
from pathlib import Path

from common import emit

from active_recognition.checkpoint import SHIPPED
from active_recognition.evaluate import EvalConfig, evaluate, summary, write_json
from active_recognition.report import training_time, write_results_page
from active_recognition.train import read_metrics

ROOT = Path(__file__).resolve().parents[1]


def main():
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--checkpoint", default=str(SHIPPED))
    ap.add_argument("--reinforce-checkpoint", default=str(SHIPPED.with_name("procedural_reinforce.pt")))
    ap.add_argument("--learned-metrics", default=str(ROOT / "docs/results/learned_metrics.csv"))
    ap.add_argument("--reinforce-metrics", default=str(ROOT / "docs/results/reinforce_metrics.csv"))
    ap.add_argument("--objects", type=int, default=0, help="0: the whole test split")
    ap.add_argument("--out", default=str(ROOT / "docs/results"))
    args = ap.parse_args()
    cfg = EvalConfig(checkpoint=args.checkpoint, reinforce_checkpoint=args.reinforce_checkpoint,
                     planners=("learned", "random", "straight", "reinforce", "oracle"),
                     objects=args.objects, out=args.out)
    results = evaluate(cfg)
    s = summary(results)
    t = training_time(read_metrics(args.learned_metrics), read_metrics(args.reinforce_metrics),
                      Path(args.out) / "training_time.png")
    s["training_time"] = t
    write_json(Path(args.out) / "summary.json", s)
    write_results_page(ROOT / "docs/RESULTS.md", s, cfg)
    print(json.dumps(s["acc_shared"]) if "acc_shared" in s else "")
    emit({"acc": s["acc"], "learned_vs_reinforce_time_ratio": t["ratio"]})


if __name__ == "__main__":
    main()
