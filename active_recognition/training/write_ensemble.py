# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""Write an ensemble of trained models (ensemble.py) as one checkpoint the node loads.

The members must share their options and classes. The checkpoint holds every member's weights
under 'model', their number under 'members', the members whose logits the `unknown` score reads
under 'judges', the first member's size prior, planner, path and training options, and the sum of
the members' training time. Fit its `unknown` answer afterwards (unknown/fit.py).

    python -m active_recognition.training.write_ensemble MEMBER.pt MEMBER.pt [...] --out ENSEMBLE.pt [--judges 0]
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

from active_recognition.argument_checks import InputError
from active_recognition.model import checkpoint
from active_recognition.model.ensemble import EnsembleConfig, MAX_MEMBERS

KEPT = ("size_prior", "default_planner", "fixed_path", "config")  # the first member's, kept in the ensemble


def combine(paths, out, judges=()):
    """Write the ensemble of the model checkpoints at `paths` to `out` (atomically), the unknown
    score read from the members `judges` (indices into `paths`; none: every one); InputError
    when they differ in options or classes, or are too few or too many."""
    if not 2 <= len(paths) <= MAX_MEMBERS:
        raise InputError(f"an ensemble needs 2 to {MAX_MEMBERS} member checkpoints, got {len(paths)}")
    ckpts = []
    for path in paths:
        ckpt = checkpoint.read(path)
        if "members" in ckpt:
            raise InputError(f"{path}: is an ensemble itself; name its members")
        checkpoint.build_model(ckpt, path)  # its weights are sound
        ckpts.append(ckpt)
    first = ckpts[0]
    for path, ckpt in zip(paths[1:], ckpts[1:]):
        if ckpt["model_args"] != first["model_args"]:
            differ = sorted(k for k in first["model_args"] if ckpt["model_args"].get(k) != first["model_args"][k])
            raise InputError(f"{path}: model options differ from {paths[0]}'s ({', '.join(differ)})")
        if list(ckpt["classes"]) != list(first["classes"]):
            raise InputError(f"{path}: classes {ckpt['classes']} differ from {paths[0]}'s {first['classes']}")
    weights = {f"members.{i}.{k}": v for i, ckpt in enumerate(ckpts) for k, v in ckpt["model"].items()}
    EnsembleConfig(**first["model_args"], members=len(ckpts), judges=list(judges))  # checks the judges
    payload = {"model": weights, "model_args": dict(first["model_args"]), "members": len(ckpts),
               "judges": list(judges),
               "classes": list(first["classes"]), "member_files": [Path(p).name for p in paths],
               **{k: first[k] for k in KEPT if k in first}}
    if all(type(c.get("elapsed")) in (int, float) for c in ckpts):  # the training it took: every member's
        payload["elapsed"] = float(sum(c["elapsed"] for c in ckpts))
    checkpoint.save(out, payload)
    checkpoint.load_model(out)  # refuse now what the recognizer would refuse
    return out


def main(argv=None):
    ap = argparse.ArgumentParser(prog="python -m active_recognition.training.write_ensemble",
                                 description=__doc__.split("\n\n")[0])
    ap.add_argument("members", nargs="+", help="model checkpoints of the same options and classes")
    ap.add_argument("--out", required=True, help="the ensemble checkpoint to write")
    ap.add_argument("--judges", type=int, nargs="+", default=[], help=(
        "the members (0-based, in the order given) whose averaged logits give the energy of the "
        "unknown answer (default: every member)"))
    args = ap.parse_args(argv)
    try:
        combine(args.members, args.out, args.judges)
    except InputError as e:
        ap.error(str(e))
    print(f"{args.out}: {len(args.members)} members; fit its unknown answer with "
          "active-recognition open-set-fit", file=sys.stderr)


if __name__ == "__main__":
    main()
