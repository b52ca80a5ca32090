# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""Outlier exposure (Hendrycks et al. 2019): training also sees objects of no known class and
learns to be unsure of them, its logits pushed toward the uniform distribution.

The outliers are the generated `unknowns` of their `train` styles only (datasets/unknowns.py):
their `val` styles choose the open-set threshold, their `test` styles are never read by training;
with `near` a share of each batch is furniture-like objects of no known class (datasets/near.py),
with `real` a share is real meshes of other classes: the real unknowns' `train` split
(datasets/real_unknowns.py, repositories apart from its val and test splits' and rebuilt under
`real_root`).
Each batch draws `outlier_batch` of them from a generator of its own, keyed like the batch's, so
the known batch (its shapes, cameras, views and every draw of its generator) stays what it is
without outliers. Pre-training renders them at random views like the known shapes; the joint
stage runs an episode of them after the known one, each step at a random candidate not yet seen
(there is no teacher without a label).
"""
from __future__ import annotations

from contextlib import contextmanager
from typing import NamedTuple

import numpy as np
import torch
from torch import nn

from active_recognition.datasets import default_cache_dir, open_dataset
from active_recognition.datasets.near import near_unknowns
from active_recognition.datasets.shapes import Shapes
from active_recognition.model.episode import Episode, EpisodeConfig, Planner, run
from active_recognition.model.policies import unavailable
from active_recognition.sensing import depth_layer
from active_recognition.sensing.reach import reach_of

STREAM = 7919  # the last key of the outlier generator: apart from every known batch's
PER_CLASS = None  # unknown objects per kind (None: the split's own count; tests take fewer)


def uniform_ce(logits):
    """The cross-entropy of softmax(logits) (N, C) to the uniform distribution, averaged over
    the N rows: mean over rows of -mean over classes of log_softmax (log C at uniform logits)."""
    return (-nn.functional.log_softmax(logits, -1).mean(-1)).mean()


def energy_margin(known, unknown, margins):
    """Liu et al. 2020's energy-bounded loss: the known rows' free energy (-logsumexp of their
    logits) held below margins[0], the unknown rows' above margins[1], each by a squared hinge
    averaged over its rows. Unlike uniform_ce it asks nothing of the known rows' softmax, only
    of the score the node ranks them by (open_set.energy)."""
    m_in, m_out = margins
    e_in, e_out = -torch.logsumexp(known, -1), -torch.logsumexp(unknown, -1)
    return (nn.functional.relu(e_in - m_in).pow(2).mean()
            + nn.functional.relu(m_out - e_out).pow(2).mean())


def unknown_loss(o, known, unknown):
    """One batch's outlier term, weighted: uniform_ce of the unknown rows, or where the batch
    carries margins, energy_margin of both."""
    if o.margins is None:
        return o.weight * uniform_ce(unknown)
    return o.weight * energy_margin(known, unknown, o.margins)


class OutlierInputs(NamedTuple):
    """One batch's outliers, made with its inputs (Trainer.inputs): nothing here is drawn from
    torch's generator, so a thread may make them ahead."""

    weight: float
    cameras: list
    views: np.ndarray           # pre-training: (n * k, 2) views; joint: (n, 2) starts
    depth: np.ndarray | None    # pre-training's images (n * k, H, W); joint: None (rendered as seen)
    rng: np.random.Generator    # the joint episode's random choices
    margins: tuple | None = None  # energy_margin's (known, unknown) free energies; None: uniform_ce


class Outliers:
    """The unknowns of the train styles seen as the known shapes are: the same camera and
    augmentation, `batch` of them to a batch, their loss weighted by `weight`."""

    def __init__(self, camera, augment, limits, weight, batch, views_per_shape, near=0.0, real=0.0,
                 real_root=None, margins=None):
        ds = open_dataset("unknowns", split="train", cache_dir=default_cache_dir(), per_class=PER_CLASS)
        self.shapes, self.augment, self.limits = Shapes(ds, camera), augment, limits
        self.weight, self.k, self.margins = weight, views_per_shape, None if margins is None else tuple(margins)
        self.near, self.near_batch, self.real, self.real_batch = None, 0, None, 0
        if near > 0:  # a share of each batch from the near unknowns (datasets/near.py)
            nds = near_unknowns("train", cache_dir=default_cache_dir(), per_class=PER_CLASS)
            self.near, self.near_batch = Shapes(nds, camera), min(len(nds), max(1, round(near * batch)))
        if real > 0:  # a share from real meshes of other classes (the real unknowns' train split)
            rds = open_dataset("real_unknowns", real_root, "train", cache_dir=default_cache_dir())  # never empty
            self.real, self.real_batch = Shapes(rds, camera), min(len(rds), max(1, round(real * batch)))
        self.batch = min(len(ds), max(0, batch - self.near_batch - self.real_batch))  # the generated ones

    def inputs(self, key, stage, starts):
        """The outliers of the batch keyed `key` (the known batch's generator key) in `stage`."""
        rng = np.random.default_rng([*key, STREAM])
        idx = rng.choice(len(self.shapes), self.batch, replace=False)
        cams = self.shapes.cameras(idx, self.augment, rng)
        for pool, n in ((self.near, self.near_batch), (self.real, self.real_batch)):
            if pool is not None:
                cams = cams + pool.cameras(rng.choice(len(pool), n, replace=False), self.augment, rng)
        if stage == "joint":
            return OutlierInputs(self.weight, cams, starts[rng.integers(0, len(starts), len(cams))],
                                 None, rng, self.margins)
        views = [self.limits.random_views(rng, self.k) for _ in cams]
        return OutlierInputs(self.weight, cams, np.concatenate(views), depth_layer.render_batch(cams, views), rng,
                             self.margins)


@contextmanager
def running_statistics_kept(model):
    """Meanwhile the model's batch norms normalise by each batch's own statistics, as in any
    training step, but leave their running statistics as they are (momentum 0): the joint
    stage's outlier episode (8 images a step) would else move them as far as a known step does.
    (Normalising the outliers by the running statistics instead, as at test time, broke a
    ModelNet10 pre-training: the network learnt to tell the two normalisations apart.)"""
    norms = [m for m in model.modules() if isinstance(m, nn.modules.batchnorm._BatchNorm)]
    kept = [m.momentum for m in norms]
    for m in norms:
        m.momentum = 0.0
    try:
        yield
    finally:
        for m, momentum in zip(norms, kept):
            m.momentum = momentum


def images(o: OutlierInputs, corrupt, device):
    """Pre-training's outlier images, corrupted as the known ones are, and their views."""
    depth = torch.from_numpy(o.depth)
    depth = (corrupt(depth) if corrupt is not None else depth).to(device)
    return depth, torch.as_tensor(o.views, dtype=torch.float32, device=device)


class RandomCandidates(Planner):
    """Each step a random candidate view not yet seen and within reach (numpy's generator)."""

    def __init__(self, candidates, rng):
        self.candidates, self.rng = candidates, rng

    def next_view(self, episode, step):
        free = ~unavailable(episode, self.candidates)
        draw = np.where(free, self.rng.random(free.shape), -1.0)  # a row with none free keeps its first
        return self.candidates[draw.argmax(1)]


def episode_loss(model, o: OutlierInputs, candidates, steps, corrupt, limits, known):
    """The joint stage: the mean over steps of unknown_loss of an outlier episode's logits, its
    views random unvisited candidates, each rendered when taken (a tenth of every candidate's
    render for a 10-step episode); `known`: the known episode's steps, step by step beside them
    (energy_margin's known rows)."""
    ep = Episode(model, EpisodeConfig(max_views=steps, entropy_threshold=0.0),
                 planner=RandomCandidates(candidates, o.rng), reach=reach_of(limits))
    with running_statistics_kept(model):
        out = run(ep, o.cameras, o.views, steps, corrupt=corrupt)
    return torch.stack([unknown_loss(o, k.logits, s.logits) for k, s in zip(known, out)]).mean()
