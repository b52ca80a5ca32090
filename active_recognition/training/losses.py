# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""The training losses: stage 1 pre-trains the classifier on single images (PretrainLoss); stage 2
runs whole episodes (JointLoss: end to end through the depth layer, the paper's; ReinforceLoss:
MV-RNN's way; ImitationLoss: FC_view learns a label-aware teacher's choice); stage 3, loc, fits
the paper's head FC_loc to FC_view's choices (LocLoss).
"""
from __future__ import annotations

import math

import numpy as np
import torch
from torch import nn

from active_recognition.argument_checks import InputError
from active_recognition.model.episode import Episode, EpisodeConfig, Planner, run
from active_recognition.model.policies import nearest_candidates, teacher_choice, unavailable
from active_recognition.sensing import depth_layer, geometry
from active_recognition.sensing.reach import reach_of
from active_recognition.training.outliers import (
    episode_loss as outlier_episode, images as outlier_images, unknown_loss,
)


def step_weights(steps, weighting="uniform"):
    """Weights of the per-step losses, summing to 1: uniform (the paper) or early (1/t, t = 1..T),
    which favours recognising after few views."""
    w = torch.ones(steps) if weighting == "uniform" else 1.0 / torch.arange(1, steps + 1)
    return w / w.sum()


def steps_loss(out, labels, weights):
    """The episode's loss: per-step cross-entropies, weighted (weights from step_weights)."""
    return sum(w * nn.functional.cross_entropy(s.logits, labels) for w, s in zip(weights, out))


class PretrainLoss(nn.Module):
    """The shape classifier on single images (wrapped whole by DDP: one forward per backward)."""

    def __init__(self, model, corrupt=None):
        super().__init__()
        self.model, self.corrupt = model, corrupt  # corrupt: the outliers' images (outliers.py)

    def forward(self, depth, labels, views=None, outliers=None):
        if outliers is None:
            logits = self.model.classify_image(depth, views)
            loss = nn.functional.cross_entropy(logits, labels)
        else:  # in one batch with the known images, so the batch norms see both (as Hendrycks et al.)
            odepth, oviews = outlier_images(outliers, self.corrupt, depth.device)
            both = self.model.classify_image(torch.cat([depth, odepth]), torch.cat([views, oviews]))
            logits = both[:len(depth)]
            loss = nn.functional.cross_entropy(logits, labels) + unknown_loss(outliers, logits, both[len(depth):])
        return loss, (logits.argmax(1) == labels).float().mean()


class JointLoss(nn.Module):
    """A whole batch of episodes, rendered through the differentiable depth layer."""

    def __init__(self, model, steps, rule, reduction, weighting="uniform", revisit=0.0,
                 corrupt=None, random_views=0.0, limits=None):
        super().__init__()
        self.model, self.steps, self.rule, self.reduction = model, steps, rule, reduction
        self.weights = step_weights(steps, weighting).tolist()
        self.revisit, self.corrupt, self.random_views = revisit, corrupt, random_views
        self.limits = limits

    def forward(self, cameras, views, labels, limits=None):
        """The batch's (loss, accuracy); `limits`: its episodes' view limits, if not the loss's."""
        ep = Episode(self.model, EpisodeConfig(max_views=self.steps, entropy_threshold=0.0),
                     random_views=self.random_views, reach=reach_of(limits or self.limits))
        out = run(ep, cameras, views, self.steps, self.rule, self.reduction, self.corrupt)
        loss = steps_loss(out, labels, self.weights)
        if self.revisit:
            loss = loss + self.revisit * revisit_penalty(torch.stack(ep.views[:self.steps], 1))
        return loss, (out[-1].logits.argmax(1) == labels).float().mean()


def increment_toward(view, goal, bound):
    """The (dtheta, dphi) (B, 2) that moves views (B, 2) toward goals (B, 2) as far as FC_loc's
    bound allows: the shorter way round in phi, each component clipped to +-bound."""
    d = goal - view
    d = torch.stack([d[:, 0], torch.remainder(d[:, 1] + math.pi, 2 * math.pi) - math.pi], -1)
    return d.clamp(-bound, bound)


def revisit_penalty(views, within=math.radians(30)):
    """VERAM's penalty on looking again where one has looked: for every view (B, T, 2) and each
    earlier one, how far the cosine of the angle between them exceeds cos(`within`), averaged.
    Differentiable in the views, so it pushes FC_loc's increments apart."""
    pos = geometry.unit_position(views)                                         # (B, T, 3)
    cos = pos @ pos.transpose(1, 2)                                              # (B, T, T)
    earlier = torch.ones_like(cos[0]).tril(-1).bool()
    return torch.relu(cos[:, earlier] - math.cos(within)).sum(1).mean()


class ReinforceLoss(nn.Module):
    """MV-RNN-style baseline: a Gaussian view policy trained with REINFORCE and a baseline.

    No gradient crosses the depth layer; the reward is a correct final prediction plus the
    entropy decrease over the episode (in units of log C); the baseline is a running mean.
    With `rule` (the hybrid policy) the renders are differentiable too: FC_loc learns from the
    depth layer's view gradient (through the sampled increments) and from REINFORCE at once.
    """

    def __init__(self, model, steps, weighting="uniform", std=0.3, entropy_weight=0.5, momentum=0.9,
                 rule=None, reduction="mean", corrupt=None, limits=None):
        super().__init__()
        self.model, self.steps, self.std, self.corrupt = model, steps, std, corrupt
        self.limits = limits
        self.rule, self.reduction = rule, reduction
        self.weights = step_weights(steps, weighting).tolist()
        self.entropy_weight, self.momentum = entropy_weight, momentum
        self.register_buffer("baseline", torch.zeros(()))

    def forward(self, cameras, views, labels, limits=None):
        ep = Episode(self.model, EpisodeConfig(max_views=self.steps, entropy_threshold=0.0),
                     exploration_std=self.std, explore_through=self.rule is not None,
                     reach=reach_of(limits or self.limits))
        out = run(ep, cameras, views, self.steps, self.rule, self.reduction, self.corrupt)
        ce = steps_loss(out, labels, self.weights)
        correct = (out[-1].logits.argmax(1) == labels).float()
        gain = torch.stack(ep.info_gain).sum(0) / math.log(out[-1].logits.shape[1])
        reward = correct + self.entropy_weight * gain
        advantage = reward - self.baseline
        with torch.no_grad():
            self.baseline.mul_(self.momentum).add_((1 - self.momentum) * reward.mean())
        policy = -(advantage.detach() * torch.stack(ep.log_probs).sum(0)).mean()
        return ce + policy, correct.mean()


class ImitationLoss(nn.Module, Planner):
    """FC_view imitates a label-aware teacher (policies.teacher_choice), DAgger-style; the
    classifier learns on the states visited.

    At every step the teacher tries each candidate view of each object with the current model
    and picks the one after which the true class is most probable (privileged, training only).
    FC_view is trained to pick it (cross-entropy over the candidates not yet visited). The next
    view is the teacher's with probability `mix`, else FC_view's, so FC_view also learns from
    states its own choices lead to. Renders are plain: no gradient crosses the depth layer.
    """

    def __init__(self, model, steps, weighting="uniform", mix=0.5, corrupt=None, limits=None,
                 distill=0.0, random_views=0.0, teacher_dtype=None, teacher_share=1.0):
        super().__init__()
        self.teacher_share = teacher_share  # the share of the candidates in reach the teacher ranks
        self.teacher_dtype = teacher_dtype  # devices.teacher_dtype: None (float32) or bfloat16
        self.distill = distill  # weight of FC_loc's loss toward the teacher's view
        self.random_views = random_views  # chance a step goes to a random unvisited candidate
        self.model, self.steps, self.mix, self.corrupt = model, steps, mix, corrupt or (lambda d, rng=None: d)
        self.weights = step_weights(steps, weighting).tolist()
        self.candidates = geometry.fibonacci_views(model.config.candidates)
        self.limits = limits

    def oracle_targets(self, cand_features, hidden, labels, visited):
        """(B,) index of the best unvisited candidate for each object (the teacher's choice)."""
        return teacher_choice(self.model, cand_features, hidden, labels, self.candidates, visited)

    def candidate_depth(self, cameras, rng=None):
        """(clean, seen): (B, K, H, W) renders of every candidate view of each camera, at the
        views (float32) an episode holds, so its steps look them up, and the teacher's copy of
        them, corrupted by the augmentation (drawn from numpy's `rng` where given, else from
        torch's generator). Trainer.inputs may make them ahead, on a thread."""
        clean = depth_layer.render_batch(cameras, float32_views(self.candidates))
        clean = clean.reshape(len(cameras), len(self.candidates), *clean.shape[1:])
        return clean, self.corrupt(torch.from_numpy(clean), rng=rng)

    def forward(self, cameras, views, labels, clean=None, seen=None, outliers=None, limits=None):
        model, k, limits = self.model, len(self.candidates), limits or self.limits
        if clean is None:
            clean, seen = self.candidate_depth(cameras)
        # the teacher reads the candidates within reach: those outside are never its choice
        inside = None if limits is None or limits.whole_sphere else torch.as_tensor(
            limits.allows(self.candidates)).nonzero()[:, 0]
        if self.teacher_share < 1:
            inside = self.teacher_set(torch.arange(k) if inside is None else inside)
        self.unranked = None if inside is None else torch.ones(k, dtype=torch.bool).index_fill_(0, inside, False)
        with torch.no_grad():
            depth = (seen if inside is None else seen[:, inside]).flatten(0, 1).to(labels.device)
            with torch.autocast(labels.device.type, self.teacher_dtype or torch.float32,
                                enabled=self.teacher_dtype is not None):
                feats = model.features(depth).float().reshape(len(cameras), -1, model.config.feature_size)
            if inside is not None:
                feats = feats.new_zeros(len(cameras), k, feats.shape[-1]).index_copy_(1, inside.to(feats.device), feats)
        self.labels, self.feats, self.head_losses = labels, feats, []
        ep = Episode(model, EpisodeConfig(max_views=self.steps, entropy_threshold=0.0),
                     planner=self, reach=reach_of(limits))
        known = [KnownViews(c, self.candidates, d) for c, d in zip(cameras, clean)]
        out = run(ep, known, views, self.steps, corrupt=self.corrupt)  # plain renders
        loss = steps_loss(out, labels, self.weights) + torch.stack(self.head_losses).mean()
        if outliers is not None:  # after the known episode, which stays what it is without
            loss = loss + outlier_episode(model, outliers, self.candidates, self.steps, self.corrupt, limits, out)
        return loss, (out[-1].logits.argmax(1) == labels).float().mean()

    def teacher_set(self, pool):
        """The candidates (indices, sorted) the teacher ranks this batch: a random teacher_share
        of `pool` (those within reach), from torch's generator, never fewer than steps + 1."""
        n = min(len(pool), max(self.steps + 1, round(self.teacher_share * len(pool))))
        return pool[torch.randperm(len(pool))[:n]].sort().values

    def next_view(self, episode, step):
        """The planner of the training episode: oracle target, FC_view loss, DAgger choice."""
        # visited, or out of reach: never a target, nor FC_view's choice
        visited = unavailable(episode, self.candidates)
        # and those the teacher did not rank: never a target, nor in FC_view's loss
        unranked = visited if self.unranked is None else visited | self.unranked.numpy()[None]
        target = self.oracle_targets(self.feats, episode.hidden, self.labels, unranked)
        scores = self.model.score_views(episode.hidden)
        masked = scores.masked_fill(torch.as_tensor(visited, device=scores.device), float("-inf"))
        ranked = masked if self.unranked is None else scores.masked_fill(
            torch.as_tensor(unranked, device=scores.device), float("-inf"))
        self.head_losses.append(nn.functional.cross_entropy(ranked, target))
        if self.distill:  # the paper's head learns the teacher's move as a continuous increment
            goal = torch.as_tensor(self.candidates, dtype=torch.float32, device=target.device)[target]
            self.head_losses.append(self.distill * nn.functional.mse_loss(
                self.model.increment(episode.hidden),
                increment_toward(episode.view.detach(), goal, self.model.config.max_step)))
        follow = torch.rand(len(target), device=target.device) < self.mix
        choice = torch.where(follow, target, masked.detach().argmax(1))
        if self.random_views:  # so the classifier also learns from sequences no head would take
            anywhere = torch.rand(masked.shape, device=target.device).masked_fill(
                torch.as_tensor(visited, device=target.device), -1.0).argmax(1)
            jump = torch.rand(len(target), device=target.device) < self.random_views
            choice = torch.where(jump, anywhere, choice)
        return self.candidates[choice.cpu().numpy()]


class LocLoss(nn.Module, Planner):
    """Stage loc: the paper's head FC_loc learns to make the move FC_view would make. Its
    increment is regressed onto the one toward FC_view's choice (increment_toward, within
    +-loc_bound), on the states of episodes that follow FC_loc itself or, at `mix` chance a step,
    FC_view (DAgger: the states FC_loc will meet); from the start of the stage FC_loc's steps reach
    loc_bound, not max_step. Only FC_loc's parameters are stepped; the
    episodes run in eval mode, so batch norm's statistics stay as the classifier left them. One
    process only: under torchrun each rank's fitting steps would go unaveraged."""

    def __init__(self, model, steps, mix=0.5, corrupt=None, limits=None):
        super().__init__()
        if torch.distributed.is_available() and torch.distributed.is_initialized() \
                and torch.distributed.get_world_size() > 1:  # its fitting steps would not be averaged
            raise InputError("stage loc runs in one process: resume the run without torchrun")
        self.model, self.steps, self.mix, self.corrupt, self.limits = model, steps, mix, corrupt, limits
        self.candidates = geometry.fibonacci_views(model.config.candidates)
        model.loc_fitted.fill_(1.0)  # from now on a step reaches loc_bound

    def collect(self, cameras, views):
        """Episodes from `views` (B, 2): (states (N, S), FC_view's increments (N, 2), whether
        FC_loc's own move landed nearest FC_view's choice (N,)), one row a step."""
        self.states, self.targets, self.agree = [], [], []
        was = self.model.training
        self.model.eval()
        with torch.no_grad():
            run(Episode(self.model, EpisodeConfig(max_views=self.steps, entropy_threshold=0.0),
                        planner=self, reach=reach_of(self.limits), mirror=False),  # answers unread
                cameras, views, self.steps, corrupt=self.corrupt)
        self.model.train(was)
        return torch.cat(self.states), torch.cat(self.targets), torch.cat(self.agree)

    def fit(self, states, targets, opt, passes, rng, batch=256):
        """`passes` passes of `opt` (over FC_loc) through the pairs in seeded minibatches: the
        mean squared error of the last pass."""
        losses = []
        for _ in range(passes):
            losses = []
            for j in np.array_split(rng.permutation(len(states)), max(1, len(states) // batch)):
                loss = nn.functional.mse_loss(self.model.increment(states[j]), targets[j])
                opt.zero_grad()
                loss.backward()
                opt.step()
                losses.append(loss.item())
        return float(np.mean(losses))

    def next_view(self, episode, step):
        """FC_view's choice among the candidates not visited (the target), or FC_loc's move."""
        hidden, view = episode.hidden, episode.view
        scores = self.model.score_views(hidden)
        scores[torch.as_tensor(unavailable(episode, self.candidates), device=scores.device)] = -math.inf
        choice = scores.argmax(1)
        goal = torch.as_tensor(self.candidates, dtype=torch.float32, device=view.device)[choice]
        own = view + self.model.increment(hidden)
        own = torch.stack(geometry.wrap_view(own[:, 0], own[:, 1]), -1)
        self.states.append(hidden)
        self.targets.append(increment_toward(view, goal, self.model.config.loc_bound))
        self.agree.append(torch.as_tensor(nearest_candidates(own.cpu().numpy(), self.candidates))
                          == choice.cpu())
        follow = torch.rand(len(view), device=view.device) < self.mix
        return torch.where(follow[:, None], goal, own)


class KnownViews:
    """A camera whose renders at some views are known already (imitation's candidates, each
    episode's every view): a trace at one of them is a look-up, any other view is cast."""

    def __init__(self, camera, views, depth):
        self.camera, self.depth = camera, depth  # depth (K, H, W) rendered at views (K, 2)
        self.known = {tuple(v): k for k, v in enumerate(np.asarray(views, dtype=np.float32))}

    def trace(self, view, normals=True):
        k = self.known.get(tuple(np.asarray(view, dtype=np.float32).ravel()))
        return k if k is not None else self.camera.trace(view, normals)

    def render_hits(self, hits):
        return self.depth[hits][None] if isinstance(hits, int) else self.camera.render_hits(hits)


def float32_views(views):
    """views (K, 2) rounded to float32 as an episode holds them (float64): a render there is the
    one an episode's view asks for, bit for bit."""
    return np.asarray(views, dtype=np.float32).astype(np.float64)
