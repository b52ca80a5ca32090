# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""Sets of views judged by the shared multi-view classifier: the headroom a planner has.

The shared classifier max-pools per-view features, so a set of views is scored from the
features of its members. With every object's features at the 50 candidate views computed once,
any subset is a max and a linear layer away:
- `best_fixed_views`: the views, the same for every object and fixed in the object frame, that
  score best on a split after a random first view (the best a non-adaptive path can do), and
  `extend_fixed_views`, the path's later views, one at a time;
- `best_subset_accuracy`: for each object the best k candidates chosen with the true label (a
  privileged ceiling).
"""
from __future__ import annotations

import itertools

import numpy as np
import torch

from active_recognition.sensing import geometry


def candidate_features(net, shapes, idx, candidates, chunk=16):
    """Shared-classifier features of objects `idx` at every candidate view: (N, K, F)."""
    out = []
    with torch.no_grad():
        for b in range(0, len(idx), chunk):
            depth = np.stack([c.render(candidates) for c in shapes.cameras(idx[b:b + chunk])])
            out.append(net.view_features(torch.from_numpy(depth)))
    return torch.cat(out)


def subset_logits(net, features, subsets):
    """features (N, K, F), subsets (S, k) candidate indices -> logits (N, S, C)."""
    pooled = features[:, torch.as_tensor(subsets)].amax(2)                 # (N, S, F)
    return net.classify(pooled)


def best_fixed_views(net, features, labels, extra=2, chunk=64):
    """Indices of the `extra` candidates that, added to any first candidate, score best on
    objects with `features` (N, K, F) and `labels`: (indices, mean accuracy over first views)."""
    k = features.shape[1]
    pairs = np.array(list(itertools.combinations(range(k), extra)))        # (P, extra)
    y = torch.as_tensor(labels)
    correct = torch.zeros(len(pairs))
    with torch.no_grad():
        for first in range(k):
            sets = np.concatenate([np.full((len(pairs), 1), first), pairs], 1)
            for b in range(0, len(features), chunk):
                logits = subset_logits(net, features[b:b + chunk], sets)  # (n, P, C)
                correct += (logits.argmax(-1) == y[b:b + chunk, None]).float().sum(0)
    best = int(correct.argmax())
    return pairs[best], float(correct[best] / (k * len(features)))


def extend_fixed_views(net, features, labels, path, extra):
    """`path` (indices after the first view) extended by `extra` candidates, one at a time: each
    the one that, added to any first candidate and the path so far, scores best (a greedy
    search: the best set of 9 among 50 views has too many members to try them all).
    -> (indices, mean accuracy over first views after each added view)."""
    path, accs = list(path), []
    y = torch.as_tensor(labels)[:, None]
    with torch.no_grad():
        for _ in range(extra):
            seen = torch.maximum(features, features[:, path].amax(1, keepdim=True))  # (N, K first, F)
            score = torch.tensor([float((net.classify(torch.maximum(seen, features[:, c:c + 1]))
                                         .argmax(-1) == y).float().mean()) for c in range(features.shape[1])])
            score[path] = -1.0  # a view already on the path adds nothing
            path.append(int(score.argmax()))
            accs.append(float(score.max()))
    return np.array(path), accs


def best_subset_accuracy(net, features, labels, size=3):
    """Fraction of objects for which some `size` candidates, chosen with the true label, are
    classified right (the subset with the highest true-class probability)."""
    sets = np.array(list(itertools.combinations(range(features.shape[1]), size)))
    hits = []
    with torch.no_grad():
        for i, y in enumerate(labels):
            logp = subset_logits(net, features[i:i + 1], sets)[0].log_softmax(-1)  # (S, C)
            hits.append(int(logp[int(logp[:, y].argmax())].argmax()) == y)
    return float(np.mean(hits))


def fixed_path(net, shapes, candidates=50, objects=400, seed=0, limits=None, indices=None, length=2):
    """The best fixed path on (a seeded sample of, or the `indices` of) `shapes`, the validation
    split: `length` candidate views (theta, phi), (length, 2), among the candidates within
    `limits` (reach.ViewLimits; None: all), that the shared classifier scores best after a random
    first view: the best pair, then (length > 2) one view at a time, each the best added to
    what the path has shown. -> (path, its accuracy there after its first view and pair)."""
    views = geometry.fibonacci_views(candidates)
    if limits is not None:
        views = limits.initial_views(candidates)
    rng = np.random.default_rng(seed)
    idx = np.asarray(indices) if indices is not None else np.sort(
        rng.permutation(len(shapes))[:objects])
    feats = candidate_features(net, shapes, idx, views)
    length = max(1, min(length, len(views) - 1))  # each candidate once; one view even for 1-view episodes
    pair, acc = best_fixed_views(net, feats, shapes.labels[idx], extra=min(2, length))
    path, _ = extend_fixed_views(net, feats, shapes.labels[idx], pair, max(0, length - 2))
    return views[path], acc
