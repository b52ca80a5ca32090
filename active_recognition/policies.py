"""View planners. Each drives the same Episode: given the episode and its last step, the next view.

learned    -- the model's own FC_loc (the episode's default; `None` here)
random     -- uniform on the sphere
straight   -- a straight path round the sphere from the initial view (Pairwise, 3DShapeNets)
reinforce  -- FC_loc of a model trained with REINFORCE (MV-RNN-style); at test time its mean
oracle     -- PRIVILEGED upper bound: renders every candidate view of the object and takes the
              one whose next prediction has the least entropy (the largest information gain)
"""
from __future__ import annotations

import math

import numpy as np
import torch

from . import geometry

PLANNERS = ("learned", "random", "straight", "reinforce", "oracle")


class RandomPlanner:
    def __init__(self, seed=0):
        self.rng = np.random.default_rng(seed)

    def next_view(self, episode, step):
        return geometry.random_views(self.rng, len(episode.view))


class StraightPlanner:
    def __init__(self, step_angle=2 * math.pi / 9):
        self.step_angle = step_angle

    def reset(self, episode):
        self.paths = [geometry.straight_path(t, p, 64, self.step_angle)
                      for t, p in episode.view.detach().numpy()]

    def next_view(self, episode, step):
        return np.stack([path[episode.steps % len(path)] for path in self.paths])


class OraclePlanner:
    """Greedy one-step information gain over a fixed candidate set. Sees the object: privileged.

    The candidates' images, hence their encoder features, are the same at every step, so each
    object's features are computed once; a step only runs the recurrent cell and FC_class.
    """

    privileged = True

    def __init__(self, cameras, candidates=50):
        self.cameras = cameras
        self.candidates = geometry.fibonacci_views(candidates)
        self.features = {}

    def next_view(self, episode, step):
        model, best = episode.model, []
        with torch.no_grad():
            for i, cam in enumerate(self.cameras):
                if i not in self.features:
                    depth = torch.from_numpy(cam.render(self.candidates))      # (K, H, W)
                    self.features[i] = model.features(depth.to(episode.view.device))
                e = self.features[i]
                hidden = model.cell(e, episode.hidden[i:i + 1].expand(len(e), -1))
                p = model.classify(hidden).softmax(-1)
                h = -(p * torch.log(p.clamp_min(1e-12))).sum(-1)
                best.append(self.candidates[int(h.argmin())])
        return np.stack(best)


def make_planner(name, cameras=None, seed=0, candidates=50):
    """A planner by name; None for the model's own view head (learned, reinforce)."""
    if name not in PLANNERS:
        raise ValueError(f"planner must be one of {PLANNERS}, got {name!r}")
    if name in ("learned", "reinforce"):
        return None
    if name == "random":
        return RandomPlanner(seed)
    if name == "straight":
        return StraightPlanner()
    if cameras is None:
        raise ValueError("the oracle planner needs the objects' cameras (it is privileged)")
    return OraclePlanner(cameras, candidates)
