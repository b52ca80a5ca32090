# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""View planners (episode.Planner). Each drives the same Episode: given the episode and its last
step, the next view.

Every planner keeps to the episode's `reach` (reach.py) when it has one: the candidate-based ones
(imitation, oracle) mask the candidates it forbids, random samples its band, and the continuous
ones (learned, reinforce, straight, fixed) are clamped into it by Episode.step.

learned    -- the model's own FC_loc (the episode's default; `None` here)
random     -- uniform on the sphere
straight   -- a straight path round the sphere from the initial view (Pairwise, 3DShapeNets)
reinforce  -- FC_loc of a model trained with REINFORCE (MV-RNN-style); at test time its mean
fixed      -- the best fixed path: after the first view, the views (fixed in the object frame, the
              same for every object) that score best on the validation split (view_sets), for as
              many views as the evaluation takes (random ones after that); the honest test of
              whether a planner adapts
imitation  -- FC_view of a model trained to imitate the oracle (train --policy imitation): the
              best-scored candidate view not yet visited; needs no mesh and renders nothing
fixed+imitation -- the best fixed path's first two views (the best pair), then imitation's: the
              views known to pay in the object frame, then the ones the model's view head picks
              from what they showed (needs no mesh either)
oracle     -- PRIVILEGED upper bound: knows the label, renders every candidate view of the
              object and takes the unvisited one after which the episode's answer (the model's
              readout) puts the true class furthest above the strongest other class, so an
              answer once right stays right wherever some view keeps it so. Imitation learns
              from its teacher (teacher_choice): the candidate after which the step's own
              classifier gives the true class the highest probability
greedy     -- PRIVILEGED, without the label: renders every candidate and takes the one whose next
              prediction has the least entropy (it may look again where it has looked; it was
              called `oracle` before issue #22)
"""
from __future__ import annotations

import math

import numpy as np
import torch

from active_recognition.argument_checks import InputError
from active_recognition.model.episode import Planner, entropy, lookahead_logits
from active_recognition.sensing import geometry

PLANNERS = ("learned", "random", "straight", "reinforce", "fixed", "imitation", "fixed+imitation",
            "oracle", "greedy")
FIXED = ("fixed", "fixed+imitation")  # the planners that follow the best fixed path
PAIR = 2  # fixed+imitation's views from the path after the first: the pair chosen together
PRIVILEGED = ("oracle", "greedy")  # they render the object's mesh: not for a robot


class RandomPlanner(Planner):
    def __init__(self, seed=0):
        self.rng = np.random.default_rng(seed)

    def next_view(self, episode, step):
        if episode.reach is not None:  # uniform on the band the robot can reach
            return episode.reach.limits.random_views(self.rng, len(episode.view))
        return geometry.random_views(self.rng, len(episode.view))


class StraightPlanner(Planner):
    def __init__(self, step_angle=2 * math.pi / 9):
        self.step_angle = step_angle

    def reset(self, episode):
        self.paths = [geometry.straight_path(t, p, 64, self.step_angle)
                      for t, p in episode.view.detach().numpy()]

    def next_view(self, episode, step):
        return np.stack([path[episode.steps % len(path)] for path in self.paths])


class FixedPlanner(Planner):
    """The views `path` (k, 2) after the first (its first `views` only, if given), the same for
    every object; then the planner `then` (default: random views)."""

    def __init__(self, path, seed=0, then=None, views=None):
        self.path = np.asarray(path, dtype=np.float64).reshape(-1, 2)[:views]
        self.then = then or RandomPlanner(seed)

    def next_view(self, episode, step):
        if episode.steps <= len(self.path):
            return np.repeat(self.path[episode.steps - 1][None], len(episode.view), 0)
        return self.then.next_view(episode, step)


def reachable(episode, candidates):
    """(K,) bool: the candidates (K, 2) the episode's robot can take (all without a reach)."""
    reach = episode.reach
    return np.ones(len(candidates), bool) if reach is None else reach.allows(candidates)


def nearest_candidates(views, candidates):
    """Index of the candidate nearest to each view (B, 2) on the sphere: (B,)."""
    pos = geometry.camera_position(*np.asarray(views, dtype=np.float64).T)          # (B, 3)
    cand = geometry.camera_position(*np.asarray(candidates, dtype=np.float64).T)    # (K, 3)
    return np.argmax(pos @ cand.T, axis=1)


def visited_mask(episode, candidates, pending=True):
    """(B, K) bool: the candidates nearest to the views the episode has taken, and to the views
    it asked for where the robot took another (so a request is not made again); with
    `pending`, the view asked for next too."""
    views = episode.marked_views(pending).cpu().numpy()
    b = views.shape[1]                                                              # (T, B, 2)
    nearest = nearest_candidates(views.reshape(-1, 2), candidates).reshape(-1, b)   # (T, B)
    mask = np.zeros((b, len(candidates)), dtype=bool)
    mask[np.broadcast_to(np.arange(b), nearest.shape), nearest] = True
    return mask


def unavailable(episode, candidates, pending=True):
    """(B, K) bool: the candidates a planner must not choose: visited (visited_mask) or out of
    the robot's reach."""
    return visited_mask(episode, candidates, pending) | ~reachable(episode, candidates)[None]


def exhausted(episode, candidates):
    """(B,) bool: every candidate the episode's robot can reach has been seen (or asked for and
    missed), so a candidate planner has nothing new to look at."""
    free = reachable(episode, candidates)
    if len(episode.marked_views(pending=False)) < free.sum():
        return np.zeros(len(episode.view), bool)  # each view marks one candidate at most
    return (visited_mask(episode, candidates, pending=False) | ~free[None]).all(1)


class ImitationPlanner(Planner):
    """FC_view's best-scored candidate view among those not yet visited (never a revisit); with
    the episode's travel_cost, the best of score - travel_cost x the angle to get there."""

    def __init__(self, model):
        if not getattr(model.config, "candidates", 0):
            raise InputError("the imitation planner needs a model with a view-scoring head "
                             "(trained with 'train --policy imitation')")
        self.candidates = geometry.fibonacci_views(model.config.candidates)

    def next_view(self, episode, step):
        with torch.no_grad():
            scores = episode.model.score_views(episode.hidden).cpu().numpy().astype(np.float64)
        cost = episode.config.travel_cost
        if cost:  # a view is worth its score less what getting there costs (log_softmax's shift cancels)
            scores -= cost * geometry.angles_to(episode.view.detach().cpu().numpy(), self.candidates)
        scores[unavailable(episode, self.candidates)] = -np.inf
        return self.candidates[scores.argmax(1)]


def teacher_choice(model, features, hidden, labels, views, visited):
    """(B,) index of the candidate after which the true class is likeliest, among those not yet
    visited: features (B, K, F) of the candidates, hidden (B, H), labels (B,), views (K, 2),
    visited (B, K) bool. The oracle's choice, and the target imitation learns."""
    with torch.no_grad():
        logp = lookahead_logits(model, features, hidden, views).log_softmax(-1)       # (B, K, C)
        true = logp.gather(2, labels[:, None, None].expand(-1, logp.shape[1], 1))[..., 0]
        true[torch.as_tensor(visited, device=true.device)] = -float("inf")
        return true.argmax(1)


def answer_margins(episode, features, views, labels, mirror_features=None):
    """(B, K): by how much the episode's answer after one more step, taken at each candidate,
    puts the true class above the strongest other (negative: the answer would be wrong).
    features (B, K, F) of the candidates (mirror_features: of their images flipped, for the
    readout mean+mirror), views (K, 2), labels (B,)."""
    with torch.no_grad():
        p = episode.lookahead(features, views, mirror_features)                      # (B, K, C)
        index = labels[:, None, None].expand(-1, p.shape[1], 1)
        return p.gather(2, index)[..., 0] - p.scatter(2, index, -1.0).amax(2)


class CandidateFeatures:
    """The encoder features of every candidate view of each object (or of their images flipped
    left to right), computed once (the candidates' images are the same at every step): the
    privileged planners' look-ahead."""

    def __init__(self, cameras, candidates=50):
        self.cameras = cameras
        self.candidates = geometry.fibonacci_views(candidates)
        self.features = {}

    def of(self, model, i, device, flipped=False):
        if (i, flipped) not in self.features:
            depth = torch.from_numpy(self.cameras[i].render(self.candidates))          # (K, H, W)
            with torch.no_grad():
                self.features[i, flipped] = model.features(
                    (depth.flip(-1) if flipped else depth).to(device))
        return self.features[i, flipped]

    def every(self, model, device, flipped=False):
        """(B, K, F): every object's candidate features."""
        return torch.stack([self.of(model, i, device, flipped) for i in range(len(self.cameras))])


class OraclePlanner(CandidateFeatures, Planner):
    """PRIVILEGED: the unvisited candidate after which the episode's answer is right by the
    widest margin (knows the label, renders the object): the upper bound of one-step planning."""

    def __init__(self, cameras, labels, candidates=50):
        super().__init__(cameras, candidates)
        self.labels = torch.as_tensor(np.asarray(labels), dtype=torch.long)

    def next_view(self, episode, step):
        model, device = episode.model, episode.view.device
        mirror = episode.mirrors
        barred = unavailable(episode, self.candidates)
        spent = barred.all(1)  # every reachable candidate seen: the oracle has nothing new
        out = ~reachable(episode, self.candidates)
        barred[spent] = out if not out.all() else False
        margin = answer_margins(episode, self.every(model, device), self.candidates,
                                self.labels.to(device),
                                self.every(model, device, flipped=True) if mirror else None)
        margin[torch.as_tensor(barred, device=device)] = -math.inf
        return self.candidates[margin.argmax(1).cpu().numpy()]


class GreedyPlanner(CandidateFeatures, Planner):
    """PRIVILEGED, without the label: the candidate whose next prediction has the least entropy
    (the largest one-step information gain); it may revisit a view."""

    def next_view(self, episode, step):
        model, best = episode.model, []
        masked = torch.as_tensor(~reachable(episode, self.candidates), device=episode.view.device)
        with torch.no_grad():
            for i in range(len(self.cameras)):
                feats = self.of(model, i, episode.view.device)
                p = lookahead_logits(model, feats[None], episode.hidden[i:i + 1],
                                     self.candidates)[0].softmax(-1)
                h = entropy(p).masked_fill(masked, math.inf)
                best.append(self.candidates[int(h.argmin())])
        return np.stack(best)


def make_planner(name, cameras=None, seed=0, candidates=50, model=None, fixed_path=None,
                 labels=None):
    """A planner by name; None for the model's own view head (learned, reinforce). The
    privileged ones need the objects' `cameras`, the oracle their `labels` too."""
    if name not in PLANNERS:
        raise InputError(f"planner must be one of {PLANNERS}, got {name!r}")
    if name in ("learned", "reinforce"):
        return None
    if name == "random":
        return RandomPlanner(seed)
    if name == "straight":
        return StraightPlanner()
    if name in ("imitation", "fixed+imitation") and model is None:
        raise InputError(f"the {name} planner needs its model")
    if name == "imitation":
        return ImitationPlanner(model)
    if name in FIXED:
        if fixed_path is None:
            raise InputError(f"the {name} planner needs its path (the fixed path: "
                             f"view_sets.fixed_path, or a checkpoint that carries 'fixed_path')")
        if name == "fixed":
            return FixedPlanner(fixed_path, seed)
        return FixedPlanner(fixed_path, seed, ImitationPlanner(model), views=PAIR)
    if cameras is None:
        raise InputError(f"the {name} planner needs the objects' cameras (it is privileged)")
    if name == "greedy":
        return GreedyPlanner(cameras, candidates)
    if labels is None:
        raise InputError("the oracle planner needs the objects' labels (it is privileged)")
    return OraclePlanner(cameras, labels, candidates)
