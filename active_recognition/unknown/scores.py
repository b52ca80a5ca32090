# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""Open-set recognition: how far an episode's evidence says its object is of none of the classes.

Every score here is "higher = more likely unknown", one per object and step (N, T):

- `msp`: 1 - the answer's maximum probability (the answer is the model's readout: with readout
  mean, already the mean of every step's class probabilities);
- `energy`: minus the log-sum-exp of the step's own logits (Liu et al. 2020);
- `mahalanobis`: the squared Mahalanobis distance of the step's recurrent state to the nearest
  class mean, a Gaussian per class with one shared covariance per step, fitted on states of
  training objects (`Gaussians`; Lee et al. 2018);
- `prototype`: 1 - the cosine similarity of the step's recurrent state to the nearest class mean
  (the same fitted means): a distance blind to the state's scale;
- `*_mean`: a score's running mean over the steps so far: evidence accumulated over the views;
  energy_mean may add a size term (`size_term`): a known size unlike every class's is evidence too.

`auroc` and `fpr_at` measure how well a score tells unknown objects from known ones;
`threshold_at` picks an operating point on validation scores of known objects.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from active_recognition.argument_checks import InputError

SCORES = ("msp", "energy", "mahalanobis", "prototype", "msp_mean", "energy_mean", "mahalanobis_mean",
          "prototype_mean")
SHRINK = 0.9  # chosen on validation (ModelNet10 val against the unknowns' val styles): 0.1 and 0.5 did worse


def running_mean(scores):
    """(N, T) -> (N, T): the mean of each row's first t scores at column t - 1."""
    scores = np.asarray(scores, dtype=float)
    return np.cumsum(scores, 1) / np.arange(1, scores.shape[1] + 1)


def msp(probs):
    """(..., C) class probabilities -> (...) 1 - their maximum."""
    return 1.0 - np.asarray(probs).max(-1)


def energy(logits):
    """(..., C) logits -> (...) the free energy, -log sum exp (stable)."""
    logits = np.asarray(logits, dtype=float)
    top = logits.max(-1, keepdims=True)
    return -(top[..., 0] + np.log(np.exp(logits - top).sum(-1)))


@dataclass
class Gaussians:
    """Class means (C, D) and the inverse of their shared covariance (D, D), of one step's states."""

    means: np.ndarray
    precision: np.ndarray

    @classmethod
    def fit(cls, features, labels, num_classes, shrink=SHRINK):
        """Fit on features (N, D) with labels (N,): the within-class covariance, shrunk toward its
        mean variance times the identity by `shrink` (states of a few hundred objects in hundreds
        of dimensions are singular otherwise)."""
        x, labels = np.asarray(features, dtype=float), np.asarray(labels)
        if x.ndim != 2 or len(x) != len(labels):
            raise InputError(f"Gaussians.fit: features {x.shape} and labels {labels.shape} do not match")
        missing = sorted(set(range(num_classes)) - set(labels.tolist()))
        if missing:
            raise InputError(f"Gaussians.fit: no training state of class(es) {missing}")
        if not 0 <= shrink <= 1:
            raise InputError(f"Gaussians.fit: shrink must lie in [0, 1], got {shrink}")
        means = np.stack([x[labels == c].mean(0) for c in range(num_classes)])
        centred = x - means[labels]
        cov = centred.T @ centred / len(x)
        target = np.trace(cov) / len(cov) if np.trace(cov) > 0 else 1.0
        cov = (1 - shrink) * cov + shrink * target * np.eye(len(cov))
        return cls(means, np.linalg.pinv(cov, hermitian=True))

    def distances(self, features):
        """(N, D) -> (N, C) squared Mahalanobis distances to every class mean."""
        d = np.asarray(features, dtype=float)[:, None] - self.means[None]
        return np.einsum("ncd,de,nce->nc", d, self.precision, d)

    def score(self, features):
        """(N, D) -> (N,) the squared distance to the nearest class."""
        return self.distances(features).min(-1)

    def cosine(self, features):
        """(N, D) -> (N,) 1 - the largest cosine similarity to a class mean (0 for a zero state)."""
        x = np.asarray(features, dtype=float)
        unit = lambda v: v / np.maximum(np.linalg.norm(v, axis=-1, keepdims=True), 1e-12)  # noqa: E731
        return 1.0 - (unit(x) @ unit(self.means).T).max(-1)


def fit_steps(states, labels, num_classes, shrink=SHRINK):
    """One `Gaussians` per step from training states (N, T, D)."""
    return [Gaussians.fit(states[:, t], labels, num_classes, shrink) for t in range(states.shape[1])]


def scores(record, gaussians=None):
    """{score: (N, T)} of a record (probs, logits, states; see `Recorder`); the Mahalanobis and
    prototype ones only with `gaussians` (one per step)."""
    out = {"msp": msp(record["probs"]), "energy": energy(record["logits"])}
    if gaussians is not None:
        out["mahalanobis"] = np.stack([g.score(record["states"][:, t]) for t, g in enumerate(gaussians)], 1)
        out["prototype"] = np.stack([g.cosine(record["states"][:, t]) for t, g in enumerate(gaussians)], 1)
    for name in list(out):
        out[f"{name}_mean"] = running_mean(out[name])
    return {name: out[name] for name in SCORES if name in out}


def auroc(known, unknown):
    """The chance that an unknown object scores above a known one (ties count half): the area
    under the ROC curve of flagging unknowns, by ranks (Mann-Whitney U)."""
    known, unknown = np.ravel(known).astype(float), np.ravel(unknown).astype(float)
    if not len(known) or not len(unknown):
        raise InputError("auroc needs known and unknown scores, got an empty group")
    _, group, counts = np.unique(np.concatenate([known, unknown]), return_inverse=True, return_counts=True)
    ranks = (np.cumsum(counts) - (counts - 1) / 2)[group]  # tied scores share their mean rank
    u = ranks[len(known):].sum() - len(unknown) * (len(unknown) + 1) / 2
    return float(u / (len(known) * len(unknown)))


def threshold_at(known, rate=0.95):
    """The smallest score that accepts (score <= threshold) at least `rate` of these known objects."""
    known = np.sort(np.ravel(known).astype(float))
    if not len(known):
        raise InputError("threshold_at needs the scores of known objects, got none")
    if not 0 < rate <= 1:
        raise InputError(f"the share of known objects to accept must lie in (0, 1], got {rate}")
    return float(known[int(np.ceil(rate * len(known))) - 1])


def fpr_at(known, unknown, rate=0.95):
    """The share of unknown objects accepted at the threshold that accepts `rate` of the known
    ones (FPR@95 for rate 0.95)."""
    return float((np.ravel(unknown) <= threshold_at(known, rate)).mean())


def judged(model, logits, state):
    """The logits the unknown score reads: an ensemble's judges' on `state` (ensemble.py), else
    the step's own `logits`."""
    judge = getattr(model, "judge_logits", None)
    return logits if judge is None else judge(state)


class Recorder:
    """An Episode's `forward` that runs the model and keeps, for each call, its logits (an
    ensemble's: its judges', ensemble.py) and the new recurrent state (`record` sorts them into steps afterwards)."""

    def __init__(self, model):
        self.model, self.calls = model, []

    def __call__(self, depth, hidden, view):
        logits, delta, hidden = self.model(depth, hidden, view)
        self.calls.append((judged(self.model, logits, hidden).detach().cpu().numpy(), hidden.detach().cpu().numpy()))
        return logits, delta, hidden

    def record(self, probs, chunk, steps, mirror):
        """{"probs": (N, T, C), "logits": (N, T, C), "states": (N, T, D)}: the calls of a rollout
        of N objects in chunks of `chunk` for `steps` steps (with `mirror`, every other call is
        the mirror image's, left out)."""
        per = steps * (2 if mirror else 1)
        if len(self.calls) % per:
            raise RuntimeError(f"recorder: {len(self.calls)} calls are not whole chunks of {per}")
        logits, states = [], []
        for b in range(0, len(self.calls), per):
            mine = self.calls[b:b + per:2 if mirror else 1]
            logits.append(np.stack([c[0] for c in mine], 1))
            states.append(np.stack([c[1] for c in mine], 1))
        self.calls = []
        out = {"probs": np.asarray(probs), "logits": np.concatenate(logits), "states": np.concatenate(states)}
        if len(out["logits"]) != len(out["probs"]):
            raise RuntimeError("recorder: the calls do not match the rollout's objects")
        return out


def prototype_steps(states, means):
    """The prototype score of each step's state: states (N, T, S) against per-step class means
    (T', C, S), step t against means[min(t, T' - 1)] (an episode longer than the fit uses its
    last step's) -> (N, T)."""
    states = np.asarray(states, dtype=float)
    return np.stack([prototype_at(states[:, t], means, t) for t in range(states.shape[1])], 1)


def prototype_mean(states, means):
    """(N, T) the running `prototype_mean` of states (N, T, S) against per-step class means."""
    return running_mean(prototype_steps(states, means))


def prototype_at(states, means, t):
    """(N,) the prototype score of states (N, S) at step t (0-based) against per-step class
    means (T', C, S): step t's means, or the last step's past the fit."""
    means = np.asarray(means, dtype=float)
    return Gaussians(means[min(t, len(means) - 1)], None).cosine(states)


def at_end(scores, stopped_at):
    """(N,) each row's score at its episode's end: scores (N, T), stopped_at (N,) 1-based."""
    return np.asarray(scores)[np.arange(len(scores)), np.asarray(stopped_at) - 1]


def confident(probs, entropy_threshold):
    """(N, T) bool: the steps whose answer (probs (N, T, C)) has entropy below the threshold."""
    p = np.clip(np.asarray(probs, dtype=float), 1e-12, 1.0)
    return -(p * np.log(p)).sum(-1) < entropy_threshold


def size_weight(model, size):
    """The weight of the checkpoint's size term for an object of `size` (metres; None: the size not
    used): its open_set `size_weight`, 0 where there is no size, no size prior or no weight."""
    if size is None or model.size_prior is None:
        return 0.0
    return (model.open_set or {}).get("size_weight", 0.0)


def size_term(model, size):
    """What the object's size adds to an episode's energy_mean before its thresholds are read: the
    size term's weight (size_weight) x the size prior's surprise at `size` (size_prior.py); 0
    where no term applies."""
    weight = size_weight(model, size)
    return float(weight * model.size_prior.surprise(size)[0]) if weight else 0.0


def own_thresholds(model, size):
    """The checkpoint's thresholds (one per step) in force for an object of `size` (metres; None:
    the size not used): those fitted with its size term, less the term; where no term applies
    (no size, no size prior), those fitted without one (`threshold_no_size`, where it has a term)."""
    entry = model.open_set
    if not size_weight(model, size):
        return entry.get("threshold_no_size", entry["threshold"])
    term = size_term(model, size)
    return [t - term for t in entry["threshold"]]


def step_thresholds(threshold, steps):
    """(steps,) the threshold in force at each step: `threshold` a number or one per step (past
    its end, its last)."""
    threshold = np.atleast_1d(np.asarray(threshold, dtype=float))
    return threshold[np.minimum(np.arange(steps), len(threshold) - 1)]


def held_thresholds(probs, scores, entropy_threshold, rate, floor=1e-6):
    """(T,) per-step thresholds under the recognizer's hold that reject no more than 1 - `rate`
    of these known objects (probs (N, T, C), running scores (N, T)) in an episode cut after any
    number of views k: step by step, among the episodes the earlier steps' thresholds have not
    ended accepted (a confident step whose score is at most its step's threshold), the least
    threshold that leaves at most (1 - rate) N of them above it at step k. Where no more than
    that many are still open, the step's threshold is the least they allow (any open known
    episode above it is one of that budget). No threshold is below `floor` (prototype_mean's
    must be above 0; -inf for a score of any sign, such as energy_mean: where none is open, the
    step's least known score)."""
    scores = np.asarray(scores, dtype=float)
    if not 0 < rate <= 1:
        raise InputError(f"the share of known objects to accept must lie in (0, 1], got {rate}")
    sure = confident(probs, entropy_threshold)
    budget = int(np.floor((1 - rate) * len(scores) + 1e-9))
    open_, out = np.ones(len(scores), bool), []
    for t in range(scores.shape[1]):
        still = np.sort(scores[open_, t])
        none = floor if np.isfinite(floor) else np.min(scores[:, t])
        thr = still[len(still) - budget - 1] if len(still) > budget else (still[0] if len(still) else none)
        out.append(max(float(thr), floor))
        open_ &= ~(sure[:, t] & (scores[:, t] <= out[-1]))
    return np.asarray(out)


def answered_unknown(scores, stops, threshold):
    """(N,) bool: the episodes whose running score (N, T) at their end `stops` (N,) 1-based is
    above that step's threshold (a number, or one per step)."""
    scores, stops = np.asarray(scores), np.asarray(stops)
    return at_end(scores, stops) > step_thresholds(threshold, scores.shape[1])[stops - 1]


def held_stops(probs, scores, entropy_threshold, threshold):
    """(N,) 1-based: where each episode ends under the recognizer's hold (hold_unknown): at the
    first step whose answer is confident (entropy below `entropy_threshold`) and whose running
    score is at most its step's threshold (a number, or one per step), else at its last step.
    probs (N, T, C), scores (N, T)."""
    scores = np.asarray(scores)
    ends = confident(probs, entropy_threshold) & (scores <= step_thresholds(threshold, scores.shape[1]))
    return np.where(ends.any(1), ends.argmax(1) + 1, ends.shape[1])
