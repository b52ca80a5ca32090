# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""A single-object recognizer for a robot: metric depth in, probabilities and next view out.

Wraps one Episode (B = 1) with what a real camera needs: every image, with its K and the pose it
was taken from, is reprojected into the model's virtual camera (reprojection.py), and the
episode goes on from the view actually taken. An image that shows too little of the object is
not classified; after `max_empty_views` of them in a row the episode ends with "no_object".
Views keep within the robot's reach (reach.py: an elevation band, and the views it could not
reach, `view_unreachable`); when no view can be had the episode ends with "no_image".
The next view comes from a planner (policies.py); "auto" is the one the checkpoint names as its
best (`default_planner`, chosen on validation by benchmarks/planners.py or
validation_camera.py), else FC_view when the model has one, else its own FC_loc. The ROS node
is a thin shell around this class.
"""
from __future__ import annotations

from contextlib import contextmanager
from dataclasses import dataclass, replace

import numpy as np
import torch

from active_recognition.argument_checks import InputError, option, validate
from active_recognition.model import checkpoint
from active_recognition.model.episode import Episode, EpisodeConfig, MAX_VIEWS, least_top_score
from active_recognition.model.network import single_step
from active_recognition.model.policies import PLANNERS, PRIVILEGED, exhausted, make_planner
from active_recognition.sensing import geometry
from active_recognition.sensing.depth_layer import CameraConfig
from active_recognition.sensing.reach import Reach, ViewLimits
from active_recognition.sensing.reprojection import Frame, auto_standoff, seen_centre
from active_recognition.unknown.decision import UnknownDecision

TRUSTED = 0.05  # an object frame this close to the centre seen (x object_size) is left alone
NODE_PLANNERS = ("auto",) + tuple(p for p in PLANNERS if p not in PRIVILEGED)  # they need the mesh


def choose_planner(name, model, ckpt):
    """The planner name `name` stands for with this checkpoint ("auto": its best)."""
    if name not in NODE_PLANNERS:
        raise InputError(f"planner must be one of {NODE_PLANNERS} (the oracle needs the object's "
                         f"mesh, and so does greedy: a robot cannot use them), got {name!r}")
    if name != "auto":
        return name
    return ckpt.get("default_planner") or ("imitation" if model.config.candidates else "learned")


@dataclass
class SensingConfig:
    # a real object: 1 mm to 100 m
    object_size: float = option(1.0, lo=1e-3, hi=100, help=(
        "metres: longest edge of the object's bounding box (from the next reset)"))
    # up to plausible.MAX_DISTANCE
    standoff: float = option(0.0, lo=0, hi=100, help=(
        "metres from the object's centre to the camera in next_view; 0 = auto: the object's "
        "bounding sphere fills the CameraInfo's narrower field of view with 10 % to spare"))
    min_object_fraction: float = option(0.003, lo=0, hi=1, hi_open=True, help=(
        "an image showing less of the object (share of the model's pixels) is not classified; "
        "the view is asked for again"))
    max_empty_views: int = option(3, lo=1, hi=MAX_VIEWS, help=(
        "so many empty images in a row end the episode: no_object"))
    box_margin: float = option(0.1, lo=0, hi=1, help=(
        "keep points this far (x object_size) outside the object's box"))
    # along the axes it sees whole; the first TRUSTED ignored
    recentre: float = option(0.25, lo=0, hi=1, help=(
        "at an object's first view, move its centre toward the centre of the box of what the view "
        "sees (a detector's centre is off; the first 5 % ignored), at most this far "
        "(x object_size); 0 = trust the object frame"))
    max_unreachable_views: int = option(2, lo=1, hi=MAX_VIEWS, help=(
        "so many unreachable views in a row, or none left, end the episode: no_image (defaults: "
        "a silent camera ends an episode in 12 s)"))
    # size_prior.py: a night stand and a dresser differ most in size
    use_size: bool = option(True, help=(
        "weigh what object_size says of the class, where the checkpoint carries a size prior "
        "(modelnet10.pt); false when object_size is a guess"))
    # unknown/scores.py: the score energy_mean; benchmarks/open_set_auroc.py measures it and its operating point
    unknown_energy: float = option(0.0, lo=-1000, hi=0, help=(
        "an episode whose mean energy over its views (-log sum exp of the logits) ends above this "
        "ends with status unknown, its best class and probability kept; 0 = never (the operating "
        "point accepting 95 % of ModelNet10's validation objects: docs/results/modelnet10/open_set.json)"))
    # unknown/scores.py: the score prototype_mean against the class means a checkpoint carries (unknown/fit.py)
    unknown_threshold: float = option(-1.0, lo=-1, hi=2, help=(
        "an episode whose mean prototype score over its views (1 - the cosine of each view's "
        "recurrent state to the nearest class mean) ends above this ends with status unknown, "
        "its best class and probability kept; -1 = the checkpoint's own score and thresholds, one "
        "for each number of views (none where it carries no open_set: active-recognition "
        "open-set-fit), 0 = never; either this or unknown_energy suffices"))
    hold_unknown: bool = option(True, help=(
        "while the views' mean score is above the unknown threshold (the checkpoint's own score, "
        "prototype_mean or energy_mean; prototype_mean where unknown_threshold is above 0; never "
        "unknown_energy), a confident answer does "
        "not end the episode: the object that looks like none of the classes is looked at until "
        "it looks like one, or for max_views"))

    def __post_init__(self):
        validate(self)
        if -1 < self.unknown_threshold < 0:
            raise InputError(f"unknown_threshold must be -1 (the checkpoint's), 0 (never) or above 0, "
                             f"got {self.unknown_threshold}")


@dataclass
class Observation:
    # classified (go on), recognized (stopped, its top probability at least the node's
    # confidence), unsure (stopped by max_views, the budget or no view left, below it), unknown
    # (stopped on an object of no known class: sensing.unknown_energy or unknown_threshold),
    # empty, moved (another view after an unreachable one), no_object, no_image or timeout (ended)
    status: str
    probs: np.ndarray | None  # (C,); None when the image was not classified
    label: str
    entropy: float | None
    next_view: tuple         # (theta, phi): the view to take next (the same one after "empty")
    done: bool
    views: int               # views classified so far
    view: tuple              # (theta, phi) the image was actually taken from
    object_fraction: float

    def result(self):
        """The JSON-able result of an episode that has ended (recognition/result)."""
        found = self.status in ("recognized", "unsure", "unknown") or \
            (self.status in ("no_image", "timeout", "canceled") and self.probs is not None)
        return {"status": self.status, "label": self.label if found else "",
                "probability": float(self.probs.max()) if found else 0.0,
                "entropy": self.entropy if found else None, "views": self.views}


class ActiveRecognizer(UnknownDecision):
    def __init__(self, checkpoint_path=None, episode=EpisodeConfig(), seed=0, planner="auto",
                 sensing=SensingConfig(), limits=ViewLimits()):
        self.model, self.classes, ckpt = checkpoint.load_model(checkpoint_path)
        size = self.model.config.image_size
        self.camera = CameraConfig(size, size, radius=self.model.config.radius)
        self.sensing = sensing
        self.planner = choose_planner(planner, self.model, ckpt)
        self.reach = Reach(limits)
        planner = make_planner(self.planner, seed=seed, model=self.model,
                               fixed_path=ckpt.get("fixed_path"))
        self.stop = episode  # the configured stop (entropy_threshold, max_views); reset may change it for one object
        self.episode = Episode(self.model, episode, planner, reach=self.reach,
                               forward=single_step(self.model), doubt=self.doubt)
        self.rng = np.random.default_rng(seed)
        # the least top probability an answer below `entropy_threshold` has (LabelInfo's threshold):
        # an episode that stops otherwise below it ends unsure
        self.confidence = least_top_score(episode.entropy_threshold, len(self.classes))
        self.initial_views = self.reach.candidates  # the paper's 50 that lie within the limits
        # the views a planner chooses among (FC_view's, else the paper's 50): once every one it
        # can reach has been used, the episode ends
        self.planner_candidates = getattr(planner, "candidates", None)
        if self.planner_candidates is None:
            self.planner_candidates = geometry.fibonacci_views(50)
        self.reset()

    @property
    def radius(self):
        return self.camera.radius

    def reset(self, view=None, sensing=None, max_views=0, entropy_threshold=None):
        """Start a new object at `view` (default: a random one of the initial views: the paper's
        50 within the elevation limits), with new sensing settings if given (they apply from
        here on). Its episode stops below `entropy_threshold` or after `max_views` (0/None: as
        configured), for this object alone."""
        if sensing is not None:
            self.sensing = sensing
        self.episode.config = replace(self.stop, max_views=int(max_views) or self.stop.max_views,
                                      entropy_threshold=self.stop.entropy_threshold if entropy_threshold is None
                                      else float(entropy_threshold))
        if view is None:
            view = self.initial_views[self.rng.integers(len(self.initial_views))]
        self.episode.reset(torch.tensor(view, dtype=torch.float32),
                           [self.sensing.object_size] if self.sensing.use_size else None)
        self.empty_views, self.no_object = 0, False
        self.no_image, self.unreachable_run, self.timed_out = False, (None, 0), False
        self.centre = np.zeros(3)  # the object's centre found in the given frame (normalised)
        self.energies = []  # each classified view's energy (open_set.energy of its logits)
        self.prototypes = []  # and its prototype score, where the checkpoint carries class means
        return tuple(float(v) for v in self.episode.view[0])

    def standoff(self, k: geometry.Intrinsics | None = None):
        """Camera distance (metres) for the next view: the `standoff` setting, else where the
        object fills camera `k` (auto_standoff), else the model's radius x object_size."""
        if self.sensing.standoff > 0:
            return self.sensing.standoff
        if k is not None:
            return auto_standoff(k, self.sensing.object_size)
        return self.radius * self.sensing.object_size

    def requested_pose(self, k=None):
        """(position (3,) metres, optical rotation (3, 3)) of the view asked for next: upright
        (geometry.upright_optical_rotation: image down toward -z), as an arm holds a camera."""
        return (geometry.camera_position(*self.view, self.standoff(k))
                + self.centre * self.sensing.object_size,
                geometry.upright_optical_rotation(*self.view))

    @property
    def view(self):
        return tuple(float(v) for v in self.episode.view[0])

    @property
    def done(self):
        return self.no_object or self.no_image or self.timed_out or bool(self.episode.done[0])

    def shot(self, metres, k=None, position=None, rotation=None):
        """A metric depth image (H, W), NaN = no return, with its camera K and pose in the object
        frame, checked and completed: without K, the model's own camera at this resolution;
        without a pose, the view asked for. -> (metres, K, position, rotation)."""
        metres = np.asarray(metres, dtype=np.float32)
        if metres.ndim != 2:
            raise InputError(f"depth must be an (H, W) image, got shape {metres.shape}")
        if position is None:
            position, rotation = self.requested_pose(k)
        if k is None:
            k = geometry.Intrinsics.from_fov(metres.shape[1], metres.shape[0], self.camera.fov_rad)
        return metres, k, np.asarray(position), rotation

    def network_input(self, metres, k=None, position=None, rotation=None):
        """The Reprojection of a depth image (see `shot` for the arguments) into the model's
        camera, about the object's centre as found so far."""
        return self.reprojected(self.shot(metres, k, position, rotation))

    def frame(self, shot, reach=0.0):
        """The shot back-projected about the object's centre as found so far (a Frame, that may
        later look up to `reach` x object_size from there)."""
        metres, k, position, rotation = shot
        size = self.sensing.object_size
        return Frame(metres, k, position - self.centre * size, rotation, self.camera, size,
                     self.sensing.box_margin, reach=reach)

    def reprojected(self, shot):
        frame = self.frame(shot)
        return frame.render(frame.kept())

    def recentred(self, frame, seen):
        """The first view's points (Kept) again, about the centre of the box of what it saw
        (seen_centre), as a detector's centre is off: the first TRUSTED of the move ignored (the
        model is trained for small errors, and a view's own estimate errs by about that much),
        the move capped at `recentre`. Twice, as the first box may have cut the object off; not
        where the image itself cut the object off. The frame's points are reused."""
        start = self.centre.copy()
        for _ in range(2):
            if len(seen.points) < 8 or seen.cut:
                break
            here = frame.position - (self.centre - start)
            found = self.centre + seen_centre(seen.points, here)
            reach = np.linalg.norm(found)
            move = min(max(reach - TRUSTED, 0.0), self.sensing.recentre)
            self.centre = found * (move / reach if reach > 0 else 0.0)
            seen = frame.kept(self.centre - start)
        return seen

    def observe(self, metres, k=None, position=None, rotation=None) -> Observation:
        """One episode step on a metric depth image (see `shot` for the arguments); the image is
        back-projected once, at the first view too."""
        if self.done:
            raise RuntimeError("the episode has ended; reset() for a new object")
        least = self.sensing.min_object_fraction
        first = self.episode.steps == 0 and self.sensing.recentre > 0
        # the centre moves at most `recentre` from 0, so at most this far from where it is
        reach = self.sensing.recentre + float(np.linalg.norm(self.centre)) if first else 0.0
        frame = self.frame(self.shot(metres, k, position, rotation), reach)
        kept = frame.kept()
        # re-centre when the image shows the object (the bound `most` settles nearly every case;
        # an image close to empty is rendered to tell)
        if first and kept.most >= least and \
                (kept.most >= 2 * least or frame.render(kept).object_fraction >= least):
            kept = self.recentred(frame, kept)
        seen = frame.render(kept)
        if seen.object_fraction < least:
            self.empty_views += 1
            self.no_object = self.empty_views >= self.sensing.max_empty_views
            status = "no_object" if self.no_object else "empty"
            return Observation(status, None, "", None, self.view, self.no_object,
                               self.episode.steps, seen.view, seen.object_fraction)
        self.empty_views = 0
        with torch.no_grad(), self.threads():
            view = torch.tensor([seen.view], dtype=torch.float32)
            step = self.episode.step(torch.from_numpy(seen.depth)[None], view=view)
        probs = step.probs[0].numpy()
        if not bool(step.done[0]) and exhausted(self.episode, self.planner_candidates)[0]:
            self.episode.stop()  # every reachable candidate used: nothing new to see
        done = bool(self.episode.done[0])
        return Observation(self.answer(probs) if done else "classified", probs,
                           self.classes[int(probs.argmax())], float(step.entropy[0]), self.view,
                           done, self.episode.steps, seen.view, seen.object_fraction)

    @contextmanager
    def threads(self):
        """torch on one thread for a step of the compact model: a 64x64 image gains nothing from
        two, and on a busy 2-core machine its OpenMP workers waited on numpy's and ROS's threads
        (a 0.4 ms step took 20-100 ms)."""
        before = torch.get_num_threads()
        if self.model.config.encoder in ("compact", "wide"):
            torch.set_num_threads(1)
        try:
            yield
        finally:
            torch.set_num_threads(before)

    def views_taken(self):
        """(steps, 2) the views the images were taken from."""
        return self.episode.visited()

    def view_unreachable(self) -> Observation:
        """No image came for the view asked for (a robot's arm could not get there, or the
        camera is silent): no planner asks for it again, and the episode moves to another view,
        the planner's next choice if it has one, else the nearest free initial view ("moved");
        it ends with "no_image" when no free view is left or after `max_unreachable_views` in a
        row. The label so far, if any view was classified, stays in the result."""
        if self.done:
            raise RuntimeError("the episode has ended; reset() for a new object")
        key = (self.episode.steps, self.empty_views)  # changes with every image observed
        run = self.unreachable_run[1] + 1 if self.unreachable_run[0] == key else 1
        self.unreachable_run = (key, run)
        self.reach.block(self.view)
        free = self.reach.free_candidates(self.episode.visited())
        self.no_image = run >= self.sensing.max_unreachable_views or not len(free)
        if not self.no_image:
            planner = self.episode.planner
            choice = planner.next_view(self.episode, None) if planner is not None else self.view
            self.episode.move_to(self.reach.keep(np.asarray(choice, np.float64).reshape(1, 2),
                                                 self.episode.visited())[0])
        return self.so_far("no_image" if self.no_image else "moved")

    def time_out(self) -> Observation:
        """The episode ran past its time (the node's episode_timeout): it ends with "timeout", the
        label so far, if any view was classified, in the result."""
        if self.done:
            raise RuntimeError("the episode has ended; reset() for a new object")
        self.timed_out = True
        return self.so_far("timeout")

    def finish(self) -> Observation:
        """End the episode on what it has seen so far (a robot-time budget spent): recognized, or
        unknown where the evidence says so."""
        if self.done:
            raise RuntimeError("the episode has ended; reset() for a new object")
        self.episode.stop()
        return self.so_far(self.answer(self.episode.probs[-1][0].detach().numpy()))

    def answer(self, probs):
        """The status of an episode that stopped on probabilities `probs` (C,): unknown where the
        evidence says so, else recognized at or above `confidence`, else unsure."""
        return "unknown" if self.unknown() else "recognized" if probs.max() >= self.confidence else "unsure"

    def so_far(self, status) -> Observation:
        """An Observation of no image, carrying the best guess so far (none before a view)."""
        probs = self.episode.probs[-1][0].detach().numpy() if self.episode.steps else None
        label = self.classes[int(probs.argmax())] if probs is not None else ""
        entropy = float(self.episode.entropies[-1][0]) if probs is not None else None
        return Observation(status, probs, label, entropy, self.view, self.done,
                           self.episode.steps, self.view, 0.0)
