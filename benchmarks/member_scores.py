# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""Whether an ensemble's members say more about unknown objects than its judge's energy alone:
every val episode shot through a simulated camera and the recognizer's own path
(camera_episodes.py), 10 views from a seeded start, no stop and no hold, each member's logits
read from the recorded state after every view. Known: ModelNet10's val split; unknown: the real
unknowns' val split (or the generated unknowns' val styles). Test objects are never read.

Scores (higher = more likely unknown), each the mean over the views so far:
- `judge_energy`: the energy of the judges' mean logits (the node's energy_mean);
- `judge_energy_t0.5`, `judge_energy_t2`: the same at temperature 0.5 and 2;
- `judge_max_logit`: minus the judges' largest logit (Hendrycks et al. 2022);
- `energy_<i>`: member i's own energy (but a sole judge's); `energy_all`: the energy of every member's mean logits;
- `disagreement_all`, `disagreement_classifiers`: the members' mutual information (the entropy of
  their mean probabilities less the mean of their entropies: a deep ensemble's disagreement), of
  every member and of the members that are no judge;
- `kl_classifier_judge`: KL(the first non-judge's probabilities || the judges').
Each with its AUROC against the known objects after 3, 6 and 10 views (and the near ones' alone).
Then each beside the judge's energy: judge_energy + w x the score, both standardised on the known
objects, w in 0..2 chosen on a random half of both groups and the AUROC read on the other half
(`--folds` halves): what a second term adds, measured on objects it was not chosen on.
Writes docs/results/modelnet10/member_scores.json (a partial run must give --out); last line JSON.

    python benchmarks/member_scores.py --root ~/data/ModelNet10 --unknowns-root ~/data/real_unknowns
        [--checkpoint ENSEMBLE.pt] [--val-objects 0] [--folds 20]
"""
import argparse

import numpy as np
import torch
from common import add_common_flags, add_unknowns_flags, emit, one_line_errors, output, results_dir

from active_recognition.datasets import default_cache_dir, open_dataset, open_splits
from active_recognition.datasets.real_unknowns import near as is_near
from active_recognition.evaluation.camera_episodes import camera_runs, recording_core
from active_recognition.evaluation.report import write_json
from active_recognition.model import checkpoint
from active_recognition.unknown import scores as open_set

STEPS, AT, SEED = 10, (3, 6, 10), 1000
WEIGHTS = np.linspace(0.0, 2.0, 21)


def member_logits(model, runs):
    """(N, STEPS, members, C) every member's logits after each view (NaN past a run's last image)."""
    out = np.full((len(runs), STEPS, model.config.members, model.config.num_classes), np.nan)
    with torch.no_grad():
        for i, run in enumerate(runs):
            if run.states:
                states = torch.as_tensor(np.stack(run.states[:STEPS]), dtype=torch.float32)
                out[i, :len(states)] = torch.stack([m.classify(s) for m, s in
                                                    zip(model.members, model.parts(states))], 1).numpy()
    return out


def softmax(logits):
    e = np.exp(logits - np.max(logits, -1, keepdims=True))
    return e / e.sum(-1, keepdims=True)


def entropy(p):
    return -(p * np.log(np.clip(p, 1e-12, 1.0))).sum(-1)


def per_view(logits, judges):
    """{score: (N, STEPS)} per view (NaN where no image) from member logits (N, STEPS, M, C)."""
    judge = logits[:, :, judges].mean(2)
    probs = softmax(logits)
    others = [m for m in range(logits.shape[2]) if m not in judges]
    mi = lambda idx: entropy(probs[:, :, idx].mean(2)) - entropy(probs[:, :, idx]).mean(2)  # noqa: E731
    out = {"judge_energy": open_set.energy(judge), "judge_energy_t0.5": 0.5 * open_set.energy(judge / 0.5),
           "judge_energy_t2": 2.0 * open_set.energy(judge / 2.0), "judge_max_logit": -judge.max(-1),
           **{f"energy_{m}": open_set.energy(logits[:, :, m]) for m in range(logits.shape[2])
              if [m] != list(judges)},
           "energy_all": open_set.energy(logits.mean(2)), "disagreement_all": mi(list(range(logits.shape[2])))}
    if len(others) > 1:
        out["disagreement_classifiers"] = mi(others)
    if others:
        p, q = probs[:, :, others[0]], softmax(judge)
        out["kl_classifier_judge"] = (p * (np.log(np.clip(p, 1e-12, 1)) - np.log(np.clip(q, 1e-12, 1)))).sum(-1)
    return out


def running(scores, t):
    """(N,) the mean of each row's first t views' scores (inf where it has none: unknown-looking)."""
    with np.errstate(all="ignore"):
        m = np.nanmean(scores[:, :t], 1)
    return np.where(np.isnan(m), np.inf, m)


def paired_halves(known, unknown, base, other, folds, rng):
    """judge_energy + w x `other` (each standardised on the known objects of the fitting half), w
    chosen on a random half of both groups, read on the other half -> {weight, auroc, alone, gain, gain_sd}."""
    rows = []
    for _ in range(folds):
        ka, kb = np.array_split(rng.permutation(len(known[base])), 2)
        ua, ub = np.array_split(rng.permutation(len(unknown[base])), 2)
        finite = {n: known[n][ka][np.isfinite(known[n][ka])] for n in (base, other)}
        z = {n: (v.mean(), v.std() or 1.0) for n, v in finite.items()}
        mix = lambda g, idx, w: ((g[base][idx] - z[base][0]) / z[base][1]  # noqa: E731
                                 + w * np.nan_to_num((g[other][idx] - z[other][0]) / z[other][1], posinf=1e6))
        w = max(WEIGHTS, key=lambda w: open_set.auroc(mix(known, ka, w), mix(unknown, ua, w)))
        rows.append((w, open_set.auroc(mix(known, kb, w), mix(unknown, ub, w)),
                     open_set.auroc(known[base][kb], unknown[base][ub])))
    r = np.array(rows)
    return {"weight": round(float(r[:, 0].mean()), 3), "auroc": round(float(r[:, 1].mean()), 4),
            "alone": round(float(r[:, 2].mean()), 4), "gain": round(float((r[:, 1] - r[:, 2]).mean()), 4),
            "gain_sd": round(float((r[:, 1] - r[:, 2]).std()), 4)}


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    add_common_flags(ap, "root", root_required=True)
    # --checkpoint by hand: its default names the shipped ensemble (EvalConfig's is None), which the JSON records
    ap.add_argument("--checkpoint", default="modelnet10.pt", help="an ensemble (python -m "
                    "active_recognition.training.write_ensemble; "
                    "default: the shipped modelnet10.pt, a judge beside a classifier)")
    ap.add_argument("--val-objects", type=int, default=0, help="the first N val objects of each group (0: all)")
    add_common_flags(ap, "camera")
    ap.add_argument("--folds", type=int, default=20, help="random halves for the weight of a second term")
    add_unknowns_flags(ap, default="real_unknowns")
    add_common_flags(ap, "out", out="docs/results/modelnet10/member_scores.json")
    args = ap.parse_args(argv)
    if args.val_objects < 0 or args.folds < 1:
        ap.error(f"--val-objects must be 0 (all) or more and --folds at least 1, got {args.val_objects}, {args.folds}")
    partial = [f for f, on in (("--checkpoint", args.checkpoint != "modelnet10.pt"),
                               ("--val-objects", args.val_objects),
                               ("--camera", args.camera != "realsense"), ("--folds", args.folds != 20),
                               ("--unknowns", args.unknowns != "real_unknowns")) if on]
    out = output(ap, args.out, str(results_dir("modelnet") / "member_scores.json"), partial)
    with one_line_errors(ap):
        path = checkpoint.model_path(args.checkpoint, "modelnet")
        model, _, ckpt = checkpoint.load_model(path)
        if "members" not in ckpt:
            ap.error(f"{path}: not an ensemble "
                     "(python -m active_recognition.training.write_ensemble A.pt B.pt --judges 0)")
        judges = list(model.config.judges) or list(range(model.config.members))
        core = recording_core(path, "auto", STEPS)
        known = open_splits("modelnet", args.root, ("val",), default_cache_dir())["val"]
        odd = open_dataset(args.unknowns, args.unknowns_root, "val", cache_dir=default_cache_dir())
        groups = {}
        for g, ds, name, root in (("known", known, "modelnet", args.root), ("unknown", odd, args.unknowns,
                                                                            args.unknowns_root)):
            n = min(args.val_objects, len(ds)) if args.val_objects else len(ds)
            runs = camera_runs(core, ds, name, "val", np.arange(n), args.camera, SEED, root, record=True)
            groups[g] = per_view(member_logits(model, runs), judges)
        near = (np.array([is_near(odd, i) for i in range(len(groups["unknown"]["judge_energy"]))])
                if args.unknowns == "real_unknowns" else np.zeros(0, bool))
    at = {t: tuple({n: running(v, t) for n, v in groups[g].items()} for g in ("known", "unknown")) for t in AT}
    k, u = at[STEPS]
    table = {}
    for name in groups["known"]:
        table[name] = {"auroc": [round(open_set.auroc(at[t][0][name], at[t][1][name]), 4) for t in AT]}
        if near.any():
            table[name]["auroc_near"] = round(open_set.auroc(k[name], u[name][near]), 4)
        if name != "judge_energy":
            table[name]["beside_judge_energy"] = paired_halves(k, u, "judge_energy", name, args.folds,
                                                               np.random.default_rng(0))
    result = {"checkpoint": path.name, "member_files": ckpt.get("member_files"), "judges": judges,
              "camera": args.camera, "unknowns": args.unknowns, "seed": SEED, "views": STEPS, "auroc_at": list(AT),
              "objects": {"known": len(k["judge_energy"]), "unknown": len(u["judge_energy"]), "near": int(near.sum())},
              "scores": table}
    if out:
        write_json(out, result)
    for name, row in table.items():
        extra = row.get("beside_judge_energy")
        print(f"{name:26s} AUROC after {AT} views {row['auroc']}"
              + (f", near {row['auroc_near']}" if near.any() else "")
              + (f"; beside judge_energy: w {extra['weight']}, {extra['auroc']} vs {extra['alone']} "
                 f"({extra['gain']:+.4f}, sd {extra['gain_sd']})" if extra else ""))
    emit(result)


if __name__ == "__main__":
    main()
