"""A single-object recognizer for a robot: metric depth in, probabilities and next view out.

Wraps one Episode (B = 1) with the conversions a camera needs: REP 118 metric depth -> the
network's normalised depth (resampled when the resolution differs at the same field of view).
The next view comes from a planner (policies.py); "auto" is the one the checkpoint names as its
best (`default_planner`, measured by benchmarks/planners.py), else FC_view when the model has
one, else its own FC_loc. The ROS node is a thin shell around this class.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import torch

from . import checkpoint, geometry
from .depth_layer import CameraConfig, normalise_depth, resample
from .episode import Episode, EpisodeConfig
from .policies import PLANNERS, make_planner

NODE_PLANNERS = ("auto",) + tuple(p for p in PLANNERS if p != "oracle")  # the oracle needs the mesh


def choose_planner(name, model, ckpt):
    """The planner name `name` stands for with this checkpoint ("auto": its best)."""
    if name not in NODE_PLANNERS:
        raise ValueError(f"planner must be one of {NODE_PLANNERS} (the oracle needs the object's "
                         f"mesh, so a robot cannot use it), got {name!r}")
    if name != "auto":
        return name
    return ckpt.get("default_planner") or ("imitation" if model.config.candidates else "learned")


@dataclass
class Observation:
    probs: np.ndarray        # (C,)
    label: str
    entropy: float
    next_view: tuple         # (theta, phi)
    done: bool
    views: int               # views used so far


class ActiveRecognizer:
    def __init__(self, checkpoint_path=None, episode=EpisodeConfig(), seed=0, planner="auto"):
        self.model, self.classes, ckpt = checkpoint.load_model(checkpoint_path or None)
        size = self.model.config.image_size
        self.camera = CameraConfig(size, size, radius=self.model.config.radius)
        self.planner = choose_planner(planner, self.model, ckpt)
        self.episode = Episode(self.model, episode, make_planner(
            self.planner, seed=seed, model=self.model, fixed_path=ckpt.get("fixed_path")))
        self.rng = np.random.default_rng(seed)
        self.initial_views = geometry.fibonacci_views(50)
        self.reset()

    @property
    def radius(self):
        return self.camera.radius

    def reset(self, view=None):
        """Start a new object at `view` (default: a random one of the 50 initial views)."""
        if view is None:
            view = self.initial_views[self.rng.integers(len(self.initial_views))]
        self.episode.reset(torch.tensor(view, dtype=torch.float32))
        return tuple(float(v) for v in self.episode.view[0])

    @property
    def view(self):
        return tuple(float(v) for v in self.episode.view[0])

    @property
    def done(self):
        return bool(self.episode.done[0])

    def network_input(self, metres):
        """(H, W) metres, NaN = no return -> (size, size) normalised depth in [0, 255]."""
        metres = np.asarray(metres, dtype=np.float32)
        if metres.shape != (self.camera.height, self.camera.width):
            metres = resample(metres, self.camera.height, self.camera.width)
        return normalise_depth(metres, self.camera)

    def observe(self, metres) -> Observation:
        """One episode step on a metric depth image taken from the current view."""
        if self.done:
            raise RuntimeError("the episode has stopped; reset() for a new object")
        with torch.no_grad():
            step = self.episode.step(torch.from_numpy(self.network_input(metres))[None])
        probs = step.probs[0].numpy()
        return Observation(probs, self.classes[int(probs.argmax())], float(step.entropy[0]),
                           self.view, bool(step.done[0]), self.episode.steps)

    def views_taken(self):
        return np.array([v[0].detach().numpy() for v in self.episode.views[:self.episode.steps]])

