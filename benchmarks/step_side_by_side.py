# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""The recognizer's 640x480 step p50 (image received -> next view published; ros_latency.py's
closed loop with the RealSense preset), two ways side by side: this checkout against another
(`--base DIR`, made with `git worktree add DIR COMMIT`), with its poses from TF against
camera/pose (`--tf`), or one model checkpoint against another (`--checkpoints A B`: an ensemble
against one of its networks, say). Runs alternate between the two, each in a process of its own, and the
figure is the ratio of their medians.

    python benchmarks/step_side_by_side.py --base DIR [--runs 3 --episodes 10]
    python benchmarks/step_side_by_side.py --tf
    python benchmarks/step_side_by_side.py --checkpoints single.pt active_recognition/checkpoints/modelnet10.pt

Last line is JSON, also written to --out when given."""
import argparse
import json
import os
import platform
import subprocess
import sys
from pathlib import Path

import numpy as np
from common import emit

from active_recognition.evaluation.report import write_json

ROOT = Path(__file__).resolve().parents[1]
ONE_RUN = """
import json, sys
root = sys.argv[1]
sys.path[:0] = [root + "/benchmarks", root]
import numpy as np
import active_recognition, ros_latency
assert active_recognition.__file__.startswith(root), active_recognition.__file__
extra = {"pose_source": sys.argv[3]} if sys.argv[3] != "topic" else {}
if sys.argv[4]:
    extra["checkpoint"] = sys.argv[4]
_, steps = ros_latency.closed_loop(int(sys.argv[2]), ros_latency.VGA, **extra)
print(json.dumps(float(np.percentile(steps, 50))))
"""


def step_p50(root, episodes, pose_source="topic", checkpoint=""):
    env = {**os.environ, "PYTHONPATH": str(root), "OMP_NUM_THREADS": "1"}
    done = subprocess.run([sys.executable, "-c", ONE_RUN, str(root), str(episodes), pose_source, checkpoint], env=env,
                          capture_output=True, text=True, timeout=1200)
    if done.returncode != 0:
        raise SystemExit(f"step_side_by_side: the run in {root} failed:\n{done.stderr[-2000:]}")
    return json.loads(done.stdout.strip().splitlines()[-1])


def cpu():
    """lscpu's model name and its vector flags, for the figures' machine."""
    info = subprocess.run(["lscpu"], capture_output=True, text=True).stdout
    lines = dict(line.split(":", 1) for line in info.splitlines() if ":" in line)
    flags = [f for f in lines.get("Flags", "").split() if f.startswith(("avx", "fma"))]
    return f"{lines.get('Model name', platform.processor()).strip()} ({', '.join(flags)})"


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    which = ap.add_mutually_exclusive_group(required=True)
    which.add_argument("--base", help="the other checkout (git worktree add DIR COMMIT)")
    which.add_argument("--tf", action="store_true", help="pose_source tf against topic, this checkout")
    which.add_argument("--checkpoints", nargs=2, metavar=("A", "B"), help="model A against model B, this checkout")
    ap.add_argument("--runs", type=int, default=3, help="runs of each, alternating")
    ap.add_argument("--episodes", type=int, default=10, help="10-view episodes a run")
    # --out by hand: no default file (written only when given)
    ap.add_argument("--out", help="JSON of the figures")
    args = ap.parse_args()
    base = Path(args.base).resolve() if args.base else ROOT
    if not (base / "benchmarks" / "ros_latency.py").exists():
        raise SystemExit(f"step_side_by_side: {base} is not a checkout of this project")
    if args.checkpoints:
        for c in args.checkpoints:
            if not Path(c).is_file():
                raise SystemExit(f"step_side_by_side: checkpoint {c}: no such file")
        arms = {name: (ROOT, "topic", str(Path(c).resolve())) for name, c in zip("AB", args.checkpoints)}
    elif args.tf:
        arms = {"topic": (ROOT, "topic", ""), "tf": (ROOT, "tf", "")}
    else:
        arms = {"base": (base, "topic", ""), "this": (ROOT, "topic", "")}
    runs = {name: [] for name in arms}
    for _ in range(args.runs):
        for name, (root, source, checkpoint) in arms.items():
            runs[name].append(step_p50(root, args.episodes, source, checkpoint))
        print(", ".join(f"{name} {r[-1]:.2f} ms" for name, r in runs.items()), flush=True)
    rev = subprocess.run(["git", "-C", str(base), "rev-parse", "--short", "HEAD"], capture_output=True,
                         text=True).stdout.strip()
    (a, ra), (b, rb) = runs.items()
    out = {"base": rev, "machine": cpu(), "episodes": args.episodes, "compared": f"{b} / {a}",
           f"{a}_step_ms_p50": ra, f"{b}_step_ms_p50": rb,
           "ratio_of_medians": float(np.median(rb) / np.median(ra))}
    if args.checkpoints:
        out["checkpoints"] = dict(zip("AB", args.checkpoints))
    if args.out:
        write_json(args.out, out)
    emit(out)


if __name__ == "__main__":
    main()
