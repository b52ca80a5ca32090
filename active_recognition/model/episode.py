# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""One active-recognition episode: read a depth image, say what it is, say where to look next.

Training, evaluation and the ROS node all drive this class. It works on a batch of objects at
once (B = 1 for a robot); views are (theta, phi) tensors and stay in the autograd graph, so the
training loop can backpropagate through the depth layer into FC_loc.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from typing import Callable, Protocol, TYPE_CHECKING, runtime_checkable

import numpy as np
import torch

from active_recognition.argument_checks import InputError, option, validate
from active_recognition.sensing.geometry import wrap_view

if TYPE_CHECKING:
    from active_recognition.model.network import RecurrentAttention
    from active_recognition.sensing.reach import Reach

MAX_VIEWS = 1000  # an episode longer than this is a typo, not a plan
# what runs the model a step: (depth (B, H, W), hidden, view (B, 2)) -> (logits, increment, hidden)
Forward = Callable[[torch.Tensor, torch.Tensor, torch.Tensor],
                   tuple[torch.Tensor, torch.Tensor, torch.Tensor]]


@dataclass
class EpisodeConfig:
    max_views: int = option(10, lo=1, hi=MAX_VIEWS, help="stop after this many views")
    # the harness's (the paper's benchmark); the node's own defaults are ROBOT below
    entropy_threshold: float = option(0.1, lo=0, help=(
        "stop once the entropy of the class probabilities (nats) is below this; 0 = never early. "
        "The recognizer node's confidence: the least top probability such an answer has "
        "(least_top_score; vision_msgs LabelInfo's threshold) is the one below which an episode "
        "stopped otherwise (max_views, time_budget, no view left) ends unsure"))
    travel_cost: float = option(0.0, lo=0, hi=100, help=(
        "what a candidate view's travel costs the imitation planner: FC_view's log-score less this "
        "x the great-circle angle (radians) from the current view; 0 = the best-scored view "
        "wherever it is"))

    def __post_init__(self):
        validate(self)


# The recognizer node's episode: the imitation planner pays for travel and the stop rule is looser,
# both chosen on ModelNet10's val split through the simulated RealSense by accuracy within 4, 8 and
# 12 robot seconds (benchmarks/seconds_validation.py; docs/results/modelnet10/seconds_validation.json)
ROBOT = EpisodeConfig(entropy_threshold=0.5, travel_cost=1.0)


@dataclass
class Step:
    logits: torch.Tensor      # (B, C)
    probs: torch.Tensor       # (B, C)
    entropy: torch.Tensor     # (B,) Shannon entropy in nats
    next_view: torch.Tensor   # (B, 2)
    done: torch.Tensor        # (B,) bool: stopped at this step or earlier


def entropy(probs):
    return -(probs * torch.log(probs.clamp_min(1e-12))).sum(-1)


@runtime_checkable
class Planner(Protocol):
    """What picks an episode's next views in place of the model's own FC_loc (policies.py; the
    training losses that steer their episodes)."""

    def next_view(self, episode: Episode, step: Step | None) -> np.ndarray | torch.Tensor:
        """(B, 2) views to take next, after `step` (None: between steps, where the view asked
        for could not be had). The episode keeps them inside its reach."""

    def reset(self, episode: Episode) -> None:
        """Optional: forget the last episode; called once the new one has its first view."""


@dataclass
class State:
    """What one episode has seen so far (Episode.reset starts a new one)."""

    view: torch.Tensor             # (B, 2) the view asked for next
    hidden: torch.Tensor           # (B, H) the recurrent state
    mirror_hidden: torch.Tensor    # the mirrored world's state (readout mean+mirror)
    done: torch.Tensor             # (B,) bool: stopped
    stopped_at: torch.Tensor       # (B,) the step each object stopped at; -1 while it goes on
    size: torch.Tensor | None      # (B,) metres: each object's longest box edge, if known
    views: list = field(default_factory=list)      # (B, 2) each: the views taken, then view
    probs: list = field(default_factory=list)      # (B, C) each: the answers
    entropies: list = field(default_factory=list)  # (B,) each: the answers' entropies
    info_gain: list = field(default_factory=list)  # (B,) each: the entropies' decreases
    probs_sum: torch.Tensor | float = 0.0  # of every step's own class probabilities (readout mean)
    requested: list = field(default_factory=list)  # (B, 2) views asked for, taken elsewhere
    log_probs: list = field(default_factory=list)  # (B,) log N(increment; FC_loc, std^2), exploring


def _read(name, doc, copy=None):
    """A read-only property of Episode: State.`name` (through `copy`: the caller's own)."""
    def get(self):
        value = getattr(self._live, name)
        return value if copy is None or value is None else copy(value)
    return property(get, doc=doc)


@dataclass
class Episode:
    model: RecurrentAttention
    config: EpisodeConfig = field(default_factory=EpisodeConfig)
    planner: Planner | None = None  # None: the model's own FC_loc
    exploration_std: float = 0.0  # > 0: sample increments from N(FC_loc, std^2) (REINFORCE)
    explore_through: bool = False  # keep the sample's path to FC_loc (the hybrid's view gradient)
    random_views: float = 0.0  # training: each next view is a random one with this chance
    # the views a robot can take (an elevation band, views found unreachable); None = the whole
    # sphere. Every planner's next view is kept inside it
    reach: Reach | None = None
    forward: Forward | None = None  # model.single_step: traced, for B = 1; None: the model itself
    # read each image's mirror image too (readout mean+mirror); None: as reads_mirror(model) says.
    # False where nobody reads the answers (training's episodes that only collect states)
    mirror: bool | None = None
    # doubt(episode, logits) -> (B,) bool, after each step's state and logits: where True a
    # confident answer does not stop the object (the recognizer's open-set hold: it looks
    # unknown; max_views still stops it)
    doubt: Callable | None = None
    _state: State | None = field(default=None, init=False, repr=False)

    def __post_init__(self):
        if self.planner is not None and not callable(getattr(self.planner, "next_view", None)):
            raise InputError(f"episode planner {self.planner!r}: has no next_view(episode, step)")

    def reset(self, initial_view, size=None):
        """Start on a new object (or batch of objects) at initial_view (2,) or (B, 2). size (B,)
        metres: each object's longest box edge (a detector's box; the node's object_size); with a
        model that carries a size prior (size_prior.py) the answer weighs what it says of each
        class."""
        device = next(self.model.parameters()).device
        view = torch.as_tensor(initial_view, dtype=torch.float32, device=device).reshape(-1, 2)
        if self.reach is not None:
            self.reach.reset()
            view = self.reach.limits.clamp(view)
        b, hidden = len(view), self.model.init_hidden(len(view), device)
        if size is not None and torch.as_tensor(size).numel() != b:
            raise InputError(f"episode size: {torch.as_tensor(size).numel()} sizes for {b} objects")
        self._state = State(view, hidden, hidden, torch.zeros(b, dtype=torch.bool, device=device),
                            torch.full((b,), -1, dtype=torch.long, device=device),
                            None if size is None else torch.as_tensor(size).reshape(b), [view])
        reset = getattr(self.planner, "reset", None)
        if reset is not None:
            reset(self)
        return self.view

    @property
    def _live(self) -> State:
        if self._state is None:
            raise RuntimeError("the episode has not started: reset(initial_view) first")
        return self._state

    # what the episode has seen, read-only: records as tuples, flags as copies
    view = _read("view", "(B, 2) the view asked for next.")
    hidden = _read("hidden", "(B, H) the recurrent state after the last step: what a planner "
                             "looks ahead from.")
    size = _read("size", "(B,) metres, each object's size as reset() was told; None: unknown.")
    views = _read("views", "(B, 2) each: the views taken, then the one asked for next.", tuple)
    probs = _read("probs", "(B, C) each step: the episode's answers.", tuple)
    entropies = _read("entropies", "(B,) each step: the answer's Shannon entropy (nats).", tuple)
    info_gain = _read("info_gain", "(B,) each step: how far it lowered the entropy (from log C "
                                   "before the first).", tuple)
    log_probs = _read("log_probs", "(B,) each step, when exploring: the log density of the "
                                   "increment sampled.", tuple)
    done = _read("done", "(B,) bool: stopped (confident, or out of views).", torch.clone)
    stopped_at = _read("stopped_at", "(B,) the number of views each object had when it stopped; "
                                     "-1 while it goes on.", torch.clone)

    @property
    def steps(self) -> int:
        """Images read so far."""
        return len(self._live.probs)

    def step(self, depth, view=None) -> Step:
        """Take the depth image(s) seen from the current view: (H, W) or (B, H, W) in [0, 255].

        view (B, 2): where the images were really taken, when that is not where the episode
        asked to look (a robot's arm); the episode goes on from there.
        """
        s = self._live
        if view is not None:
            s.requested.append(s.view.detach())  # marked as visited too
            self.move_to(view)
        depth = torch.as_tensor(depth, dtype=torch.float32, device=s.view.device)
        depth = depth.reshape(len(s.view), *depth.shape[-2:])
        forward = self.forward or self.model
        logits, delta, s.hidden = forward(depth, s.hidden, s.view)
        probs = logits.softmax(-1)
        if self.mirrors:
            flipped, _, s.mirror_hidden = forward(depth.flip(-1), s.mirror_hidden, mirrored(s.view))
            probs = (probs + flipped.softmax(-1)) / 2
        probs = self.answer(probs)
        h = entropy(probs)
        prev = s.entropies[-1] if s.entropies else torch.full_like(h, math.log(probs.shape[-1]))
        s.info_gain.append((prev - h).detach())
        s.probs.append(probs)
        s.entropies.append(h.detach())
        stop = h.detach() < self.config.entropy_threshold
        if self.doubt is not None:
            stop = stop & ~torch.as_tensor(self.doubt(self, logits), dtype=torch.bool, device=stop.device)
        stop = stop | (self.steps >= self.config.max_views)
        s.stopped_at = torch.where(stop & ~s.done, self.steps, s.stopped_at)
        s.done = s.done | stop
        step = Step(logits, probs, h, None, self.done)
        if self.planner is None:
            step.next_view = self.own_next_view(delta)
        else:
            step.next_view = torch.as_tensor(self.planner.next_view(self, step), dtype=torch.float32,
                                             device=s.view.device)
        if self.reach is not None:
            step.next_view = self.reach.keep(step.next_view, self.visited)
        s.view = step.next_view
        s.views.append(s.view)
        return step

    def own_next_view(self, delta):
        """The model's own next views (B, 2) from FC_loc's increments `delta` (B, 2): sampled
        around them when exploring, a random view at `random_views` chance."""
        s = self._live
        if self.exploration_std > 0:
            sample = delta + self.exploration_std * torch.randn_like(delta)
            s.log_probs.append(-((sample.detach() - delta) ** 2).sum(-1)
                               / (2 * self.exploration_std ** 2))
            delta = sample if self.explore_through else sample.detach()
        theta, phi = wrap_view(s.view[:, 0] + delta[:, 0], s.view[:, 1] + delta[:, 1])
        view = torch.stack([theta, phi], -1)
        if self.random_views > 0:  # so the classifier learns from any sequence of views
            jump = torch.rand(len(theta), device=theta.device) < self.random_views
            anywhere = torch.stack([torch.arccos(1 - 2 * torch.rand_like(theta)),
                                    (2 * torch.rand_like(phi) - 1) * math.pi], -1)
            view = torch.where(jump[:, None], anywhere, view)
        return view

    @property
    def mirrors(self):
        """Whether this episode reads each image's mirror image too."""
        return reads_mirror(self.model) if self.mirror is None else self.mirror

    def answer(self, probs):
        """The class probabilities the episode answers, from this step's own (the model's
        readout: these, or the mean of every step's so far), times what the objects' sizes say
        of each class where the model has a size prior and the episode knows the sizes."""
        s = self._live
        if self.model.config.readout != "last":
            s.probs_sum = s.probs_sum + probs
            probs = s.probs_sum / (self.steps + 1)
        prior = getattr(self.model, "size_prior", None)
        return probs if prior is None or s.size is None else prior.apply(probs, s.size)

    def lookahead(self, features, views, mirror_features=None):
        """(B, K, C): the answer (before any size prior) after one more step, taken at each
        candidate view (K, 2), from the candidates' features (B, K, F) (mirror_features: of their
        images flipped, for the readout mean+mirror)."""
        s = self._live
        p = lookahead_logits(self.model, features, s.hidden, views).softmax(-1)
        if mirror_features is not None:
            flipped = mirrored(torch.as_tensor(views, dtype=torch.float32))
            p = (p + lookahead_logits(self.model, mirror_features, s.mirror_hidden,
                                      flipped).softmax(-1)) / 2
        if self.model.config.readout != "last":  # the mean of every step's, this one's included
            p = (s.probs_sum[:, None] + p) / (self.steps + 1)
        return p

    def marked_views(self, pending=True):
        """(N, B, 2): every view taken, and each asked for but taken elsewhere (a request made
        once is not made again); with `pending`, the view asked for next too."""
        s = self._live
        views = s.views if pending else s.views[:self.steps]
        return torch.stack(list(views) + s.requested).detach()

    def visited(self):
        """(steps, 2) numpy views taken so far by a single object (B = 1); empty otherwise."""
        if len(self.view) != 1 or not self.steps:
            return np.zeros((0, 2))
        return torch.cat(self._live.views[:self.steps]).detach().cpu().numpy()

    def move_to(self, view):
        """Ask for `view` (B, 2) instead of the view pending (a robot could not reach that one,
        or took its image elsewhere)."""
        s = self._live
        s.view = torch.as_tensor(view, dtype=torch.float32, device=s.view.device).reshape(s.view.shape)
        s.views[-1] = s.view

    def stop(self):
        """End the episode now for the objects still going on (nothing new is left to see)."""
        s = self._live
        s.stopped_at = torch.where(s.done, s.stopped_at, self.steps)
        s.done = torch.ones_like(s.done)

    def fork(self, **settings):
        """A copy of the episode as it is now, with its own records: stepping it leaves this one
        as it was (one step tried at each of several views). `settings` replace fields of the
        copy (planner=None: FC_loc plans its next view)."""
        twin = replace(self, **settings)
        s = self._live
        twin._state = replace(s, **{k: list(getattr(s, k)) for k in (
            "views", "probs", "entropies", "info_gain", "requested", "log_probs")})
        return twin


def lookahead_logits(model, features, hidden, views):
    """Class logits after one more step from each state, with each candidate view:
    features (B, K, F) of the candidates, hidden (B, H), views (K, 2) -> (B, K, C)."""
    b, k = features.shape[:2]
    views = torch.as_tensor(views, dtype=torch.float32, device=features.device)
    h = model.advance(features.reshape(b * k, -1), hidden.repeat_interleave(k, 0), views.repeat(b, 1))
    return model.classify(h).reshape(b, k, -1)


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
        corrupt=None, size=None):
    """Close the loop in simulation: render each camera at the episode's view, step, repeat.

    cameras: one DepthCamera per object; initial_views (B, 2). With `rule` ("paper"/"surface")
    the renders are differentiable in the view (training); without, they are plain.
    Runs `steps` steps (default: the episode's max_views) regardless of early stopping; the
    episode records where each object would have stopped. `corrupt` (training augmentation)
    maps each batch of images to a damaged copy; `size` (B,) the objects' sizes (Episode.reset).
    Returns the list of Steps.
    """
    from active_recognition.sensing.depth_layer import render_views

    episode.reset(torch.as_tensor(initial_views, dtype=torch.float32), size)
    out = []
    for _ in range(steps or episode.config.max_views):
        view = episode.view
        if rule is None:
            view = view.detach()
        depth = render_views(view.double(), cameras, rule or "paper", reduction).float()
        out.append(episode.step(depth if corrupt is None else corrupt(depth)))
    return out


def least_top_score(entropy_threshold, n_classes):
    """The smallest top probability a distribution over `n_classes` can have with an entropy
    (nats) below `entropy_threshold`: the score a recognised class has at least (vision_msgs
    LabelInfo's threshold). The least entropy at top probability p puts p on floor(1/p) classes
    and the rest on one; it falls as p grows, so p is found by bisection."""
    def least_entropy(p):
        k = math.floor(1 / p)
        rest = max(1.0 - k * p, 0.0)
        return -k * p * math.log(p) - (rest * math.log(rest) if rest > 0 else 0.0)

    lo, hi = 1.0 / n_classes, 1.0
    if entropy_threshold >= least_entropy(lo):
        return lo
    for _ in range(60):
        mid = (lo + hi) / 2
        lo, hi = (lo, mid) if least_entropy(mid) < entropy_threshold else (mid, hi)
    return hi
