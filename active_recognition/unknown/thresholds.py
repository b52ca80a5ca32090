# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""The thresholds of the unknown answer a checkpoint carries: its `open_set` entry (the score it
was fitted for, the class means of the recurrent state per step, a threshold per step, what it
was fitted on), checked when the checkpoint loads (model/checkpoint.build_model). fit.py writes
it; decision.py reads it."""
from __future__ import annotations

import math

import torch

from active_recognition.argument_checks import InputError


OPEN_SET_SCORE = "prototype_mean"  # the default score of a checkpoint's "open_set" (unknown/fit.py)
OPEN_SET_SCORES = ("prototype_mean", "energy_mean")  # the scores an open_set may carry thresholds for


def checked_open_set(entry, num_classes, state_size):
    """A checkpoint's `open_set` entry checked: {"score": one of OPEN_SET_SCORES, "means": float
    tensor (T, C, S), "threshold": a number or one per step (a list or 1-D tensor; past its end,
    the last): in (0, 2] for prototype_mean (1 - a cosine), finite for energy_mean, "fitted_on":
    dict, optionally "size_weight": a number >= 0 (scores.size_term) and "threshold_no_size" (as
    threshold: those in force where the size is not used)}; InputError naming what is wrong. The
    thresholds come back as lists of floats, one per step (a single number: a list of one)."""
    if not isinstance(entry, dict) or not {"score", "means", "threshold"} <= set(entry):
        raise InputError("open_set must be a dict with score, means and threshold "
                         f"(got {sorted(entry) if isinstance(entry, dict) else type(entry).__name__})")
    if entry["score"] not in OPEN_SET_SCORES:
        raise InputError(f"open_set score must be one of {', '.join(OPEN_SET_SCORES)}, got {entry['score']!r}")
    means = entry["means"]
    if not torch.is_tensor(means) or not means.is_floating_point() or means.ndim != 3 or not len(means):
        raise InputError(f"open_set means must be a float tensor (steps, classes, state size), got "
                         f"{tuple(means.shape) if torch.is_tensor(means) else type(means).__name__}")
    if tuple(means.shape[1:]) != (num_classes, state_size):
        raise InputError(f"open_set means {tuple(means.shape)} do not fit the model: (steps, {num_classes} "
                         f"classes, state size {state_size}) expected")
    if not torch.isfinite(means).all():
        raise InputError("open_set means hold NaN or infinite values")
    if entry["score"] == "energy_mean":
        valid, what = math.isfinite, "of energy_mean must be a finite number"
    else:
        valid, what = (lambda t: 0 < t <= 2), "must be a number in (0, 2] (1 - a cosine)"
    lists = {}
    for key in ("threshold", "threshold_no_size"):
        if key not in entry:
            continue
        threshold = entry[key]
        steps = threshold.tolist() if torch.is_tensor(threshold) and threshold.ndim == 1 else (
            list(threshold) if isinstance(threshold, (list, tuple)) else [threshold])
        if not steps or any(type(t) not in (int, float) or not valid(t) for t in steps):
            raise InputError(f"open_set {key} {what} or one per step, got {threshold!r}")
        lists[key] = [float(t) for t in steps]
    if not isinstance(entry.get("fitted_on", {}), dict):
        raise InputError("open_set fitted_on must be a dict")
    weight = entry.get("size_weight", 0.0)
    if type(weight) not in (int, float) or not (math.isfinite(weight) and weight >= 0):
        raise InputError(f"open_set size_weight must be a number >= 0 (0: no size term), got {weight!r}")
    return {**entry, "means": means.float(), **lists}
