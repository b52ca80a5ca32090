# Copyright 2026 active_recognition maintainers
#
# Licensed under the Apache License, Version 2.0 (the "License");
# you may not use this file except in compliance with the License.
# You may obtain a copy of the License at
#
#     http://www.apache.org/licenses/LICENSE-2.0
#
# Unless required by applicable law or agreed to in writing, software
# distributed under the License is distributed on an "AS IS" BASIS,
# WITHOUT WARRANTIES OR CONDITIONS OF ANY KIND, either express or implied.
# See the License for the specific language governing permissions and
# limitations under the License.

"""One active-recognition episode: read a depth image, say what it is, say where to look next.

Training, evaluation and the ROS node all drive this class. It works on a batch of objects at
once (B = 1 for a robot); views are (theta, phi) tensors and stay in the autograd graph, so the
training loop can backpropagate through the depth layer into FC_loc.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
import torch

from .geometry import wrap_view
from .validation import option, validate

MAX_VIEWS = 1000  # an episode longer than this is a typo, not a plan


@dataclass
class EpisodeConfig:
    max_views: int = option(10, lo=1, hi=MAX_VIEWS, help="stop after this many views")
    entropy_threshold: float = option(0.1, lo=0, help="stop once the entropy of the class "
                                                      "probabilities (nats) is below this; 0 = never early")

    def __post_init__(self):
        validate(self)


@dataclass
class Step:
    logits: torch.Tensor      # (B, C)
    probs: torch.Tensor       # (B, C)
    entropy: torch.Tensor     # (B,) Shannon entropy in nats
    next_view: torch.Tensor   # (B, 2)
    done: torch.Tensor        # (B,) bool: stopped at this step or earlier


def entropy(probs):
    return -(probs * torch.log(probs.clamp_min(1e-12))).sum(-1)


@dataclass
class Episode:
    model: torch.nn.Module
    config: EpisodeConfig = field(default_factory=EpisodeConfig)
    planner: object = None  # None: the model's own FC_loc; else planner.next_view(episode, step)
    exploration_std: float = 0.0  # > 0: sample increments from N(FC_loc, std^2) (REINFORCE)
    explore_through: bool = False  # keep the sample's path to FC_loc (the hybrid's view gradient)
    random_views: float = 0.0  # training: each next view is a random one with this chance
    # the views a robot can take (reach.Reach: an elevation band, views found unreachable);
    # None = the whole sphere. Every planner's next view is kept inside it
    reach: object = None
    # what runs the model a step (model.single_step: traced, for B = 1); None: the model itself
    forward: object = None
    # read each image's mirror image too (readout mean+mirror); None: as reads_mirror(model) says.
    # False where nobody reads the answers (training's episodes that only collect states)
    mirror: bool | None = None
    # (B,) metres: each object's longest box edge (a detector's box; the node's object_size). With
    # a model that carries a size prior (size_prior.py) the answer weighs what it says of each class
    size: object = None

    def reset(self, initial_view):
        """Start on a new object (or batch of objects) at initial_view (2,) or (B, 2)."""
        device = next(self.model.parameters()).device
        view = torch.as_tensor(initial_view, dtype=torch.float32, device=device)
        self.view = view.reshape(-1, 2)
        if self.reach is not None:
            self.reach.reset()
            self.view = self.reach.limits.clamp(self.view)
        self.hidden = self.model.init_hidden(len(self.view), device)
        self.mirror_hidden = self.hidden  # the mirrored world's state (readout mean+mirror)
        self.views, self.probs, self.entropies, self.info_gain = [self.view], [], [], []
        self.probs_sum = 0.0  # of every step's own class probabilities (readout mean)
        self.requested = []  # views asked for but taken elsewhere (a robot's arm): (B, 2) each
        self.log_probs = []  # log N(increment; FC_loc, std^2) per step, when exploring
        self.done = torch.zeros(len(self.view), dtype=torch.bool, device=device)
        self.stopped_at = torch.full((len(self.view),), -1, dtype=torch.long, device=device)
        if self.planner is not None and hasattr(self.planner, "reset"):
            self.planner.reset(self)
        return self.view

    @property
    def steps(self):
        return len(self.probs)

    def step(self, depth, view=None) -> Step:
        """Take the depth image(s) seen from the current view: (H, W) or (B, H, W) in [0, 255].

        view (B, 2): where the images were really taken, when that is not where the episode
        asked to look (a robot's arm); the episode goes on from there.
        """
        if view is not None:
            self.requested.append(self.views[-1].detach())  # marked as visited too
            self.view = torch.as_tensor(view, dtype=torch.float32,
                                        device=self.view.device).reshape(self.view.shape)
            self.views[-1] = self.view
        depth = torch.as_tensor(depth, dtype=torch.float32, device=self.view.device)
        depth = depth.reshape(len(self.view), *depth.shape[-2:])
        forward = self.forward or self.model
        logits, delta, self.hidden = forward(depth, self.hidden, self.view)
        probs = logits.softmax(-1)
        if self.mirrors:
            flipped, _, self.mirror_hidden = forward(depth.flip(-1), self.mirror_hidden,
                                                     mirrored(self.view))
            probs = (probs + flipped.softmax(-1)) / 2
        probs = self.answer(probs)
        h = entropy(probs)
        prev = self.entropies[-1] if self.entropies else torch.full_like(h, math.log(probs.shape[-1]))
        self.info_gain.append((prev - h).detach())
        self.probs.append(probs)
        self.entropies.append(h.detach())
        stop = (h.detach() < self.config.entropy_threshold) | (self.steps >= self.config.max_views)
        newly = stop & ~self.done
        self.stopped_at[newly] = self.steps
        self.done = self.done | stop
        step = Step(logits, probs, h, None, self.done.clone())
        if self.planner is None:
            if self.exploration_std > 0:
                sample = delta + self.exploration_std * torch.randn_like(delta)
                self.log_probs.append(-((sample.detach() - delta) ** 2).sum(-1)
                                      / (2 * self.exploration_std ** 2))
                sample = sample if self.explore_through else sample.detach()
                delta = sample
            theta, phi = wrap_view(self.view[:, 0] + delta[:, 0], self.view[:, 1] + delta[:, 1])
            step.next_view = torch.stack([theta, phi], -1)
            if self.random_views > 0:  # so the classifier learns from any sequence of views
                jump = torch.rand(len(theta), device=theta.device) < self.random_views
                anywhere = torch.stack([torch.arccos(1 - 2 * torch.rand_like(theta)),
                                        (2 * torch.rand_like(phi) - 1) * math.pi], -1)
                step.next_view = torch.where(jump[:, None], anywhere, step.next_view)
        else:
            step.next_view = torch.as_tensor(self.planner.next_view(self, step), dtype=torch.float32,
                                             device=self.view.device)
        if self.reach is not None:
            step.next_view = self.reach.keep(step.next_view, self.visited)
        self.view = step.next_view
        self.views.append(self.view)
        return step

    @property
    def mirrors(self):
        """Whether this episode reads each image's mirror image too."""
        return reads_mirror(self.model) if self.mirror is None else self.mirror

    def answer(self, probs):
        """The class probabilities the episode answers, from this step's own (the model's
        readout: these, or the mean of every step's so far), times what the objects' sizes say
        of each class where the model has a size prior and the episode knows the sizes."""
        if self.model.config.readout != "last":
            self.probs_sum = self.probs_sum + probs
            probs = self.probs_sum / (self.steps + 1)
        prior = getattr(self.model, "size_prior", None)
        return probs if prior is None or self.size is None else prior.apply(probs, self.size)

    def visited(self):
        """(steps, 2) numpy views taken so far by a single object (B = 1); empty otherwise."""
        if len(self.view) != 1 or not self.steps:
            return np.zeros((0, 2))
        return torch.cat(self.views[:self.steps]).detach().cpu().numpy()

    def move_to(self, view):
        """Ask for `view` (2,) instead of the view pending (a robot could not reach that one)."""
        self.view = torch.as_tensor(view, dtype=torch.float32,
                                    device=self.view.device).reshape(self.view.shape)
        self.views[-1] = self.view


def reads_mirror(model):
    """Whether an episode of `model` reads each image's mirror image too: readout mean+mirror, at
    evaluation (in training each step's own logits are what the loss reads)."""
    return model.config.readout.endswith("+mirror") and not model.training


def mirrored(view):
    """The view (B, 2) of the object mirrored x -> -x from which it looks as the image flipped
    left to right looks from `view`: (theta, pi - phi)."""
    theta, phi = wrap_view(view[:, 0], math.pi - view[:, 1])
    return torch.stack([theta, phi], -1)


def run(episode: Episode, cameras, initial_views, steps=None, rule=None, reduction="mean",
        corrupt=None):
    """Close the loop in simulation: render each camera at the episode's view, step, repeat.

    cameras: one DepthCamera per object; initial_views (B, 2). With `rule` ("paper"/"surface")
    the renders are differentiable in the view (training); without, they are plain.
    Runs `steps` steps (default: the episode's max_views) regardless of early stopping; the
    episode records where each object would have stopped. `corrupt` (training augmentation)
    maps each batch of images to a damaged copy. Returns the list of Steps.
    """
    from .depth_layer import render_views

    episode.reset(torch.as_tensor(initial_views, dtype=torch.float32))
    out = []
    for _ in range(steps or episode.config.max_views):
        view = episode.view
        if rule is None:
            view = view.detach()
        depth = render_views(view.double(), cameras, rule or "paper", reduction).float()
        out.append(episode.step(depth if corrupt is None else corrupt(depth)))
    return out
