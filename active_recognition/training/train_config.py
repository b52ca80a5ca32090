# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""The options of a training run (TrainConfig): each field is the one definition of its YAML key,
its `train` flag and its entry in docs/options.md. A preset's keys are the fields' names; the view
limits sit beside them (min_elevation), the model's under `model:`."""
from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

from active_recognition.argument_checks import (
    Check, InputError, SEED_MAX, as_dict, check_mapping, group, load_yaml, nested, option, validate,
)
from active_recognition.datasets import NAMES
from active_recognition.datasets.augment import Augment
from active_recognition.model.network import ModelConfig, initial_step_bias
from active_recognition.sensing.depth_layer import GRADIENT_RULES
from active_recognition.sensing.reach import ViewLimits
from active_recognition.training.devices import PRECISIONS
from active_recognition.training.lr_schedule import SCHEDULES

STAGES = ("pretrain", "joint", "loc")
STEP_WEIGHTINGS = ("uniform", "early")
POLICIES = ("learned", "reinforce", "hybrid", "imitation")
MAX_EPOCHS = 100_000
AUGMENT = "augment: "


@dataclass
class TrainConfig:
    dataset: str = option("procedural", choices=NAMES, help="dataset layout")
    root: str | None = option(None, kind=str, optional=True, length=(1, None),
                              help="dataset root folder")
    out: str = option("runs/procedural", length=(1, None),
                      help="run folder for checkpoints and metrics.csv")
    stage: str = option("all", choices=STAGES + ("all",), help=(
        "which stage(s) to run (loc goes with --resume on a run whose joint stage is done)"))
    policy: str = option("learned", choices=POLICIES, help=(
        "how the view head learns: end to end through the depth layer (learned), REINFORCE, both "
        "at once (hybrid), or FC_view imitating a label-aware teacher (imitation, needs "
        "--candidates)"))
    imitation_mix: float = option(0.5, lo=0, hi=1, help=(
        "imitation: chance that a training step follows the teacher"))
    distill_loc: float = option(0.0, lo=0, help=(
        "imitation: weight of FC_loc's loss toward the teacher's view, so the paper's continuous "
        "head learns where the teacher looks"))
    revisit_penalty: float = option(0.0, lo=0, help=(
        "learned: weight of the penalty on views within 30 degrees of earlier ones (VERAM's)"))
    random_views: float = option(0.0, lo=0, hi=1, help=(
        "learned, imitation: chance that a training step looks somewhere random (imitation: an "
        "unvisited candidate), so the classifier learns from any sequence of views"))
    # outliers.py: objects of no known class (the unknowns' train styles), taught to be unsure of
    outliers: float = option(0.0, lo=0, help=(
        "weight of the outlier-exposure loss: the cross-entropy to the uniform distribution of "
        "generated unknown objects of their train styles, in pre-training's images and in an "
        "episode of random views after each joint batch (policy imitation); 0 = off"))
    outlier_batch: int = option(8, lo=1, hi=100_000, help="--outliers: unknown objects per batch")
    near_outliers: float = option(0.0, lo=0, hi=1, help=(
        "--outliers: the share of each batch's unknown objects that are furniture-like (stools, "
        "shelves, cabinets, appliances, pianos, mantels: datasets/near.py), the rest the unknowns'"))
    real_outliers: float = option(0.0, lo=0, hi=1, help=(
        "--outliers: the share of each batch's unknown objects that are real meshes of other "
        "classes: the real unknowns' train split under --real-outliers-root (rebuilt by "
        "tools/fetch_real_unknowns.py; never its val or test split)"))
    real_outliers_root: str = option("", help="--real-outliers: the real unknowns' folder")
    outlier_margins: list | None = option(None, kind=list, optional=True, length=(2, 2), items=Check(float),
                                          metavar=("KNOWN", "UNKNOWN"), help=(
                                              "--outliers: instead of the cross-entropy to uniform, Liu et "
                                              "al.'s energy-bounded loss: squared hinges holding the known "
                                              "objects' free energy (-logsumexp of the logits) below KNOWN "
                                              "and the unknown ones' above UNKNOWN (default: off)"))
    # every training view keeps inside the views a robot can take
    limits: ViewLimits = nested(ViewLimits, flat=True)
    band_share: float = option(0.0, lo=0, hi=1, help=(
        "joint stage: the share of batches whose episodes keep to the band above the object's "
        "centre (elevation 0 and up, the recognizer's default: an object on a floor), the rest "
        "within min_elevation's; for a model good on the whole sphere and in the band"))
    pretrain_epochs: int = option(6, lo=0, hi=MAX_EPOCHS, help="stage 1 epochs")
    joint_epochs: int = option(6, lo=0, hi=MAX_EPOCHS, help="stage 2 epochs")
    loc_epochs: int = option(0, lo=0, hi=MAX_EPOCHS, help=(
        "stage loc (imitation, needs --loc-hidden): rounds in which FC_loc, the paper's head, "
        "learns to move toward FC_view's choice, on episodes whose steps follow FC_loc or, at "
        "--imitation-mix's chance, FC_view (0: no stage loc)"))
    batch_size: int = option(32, lo=1, hi=100_000, help="shapes per batch")
    views_per_shape: int = option(4, lo=1, hi=1000, help="pre-training images per shape per batch")
    steps: int = option(10, lo=1, hi=100, help="views per training episode")
    # Adam; the paper's SGD used 0.01
    lr_pretrain: float = option(1e-3, lo=0, lo_open=True, help="stage 1 learning rate")
    lr_joint: float = option(3e-4, lo=0, lo_open=True, help="stage 2 learning rate (the paper: 0.001)")
    lr_loc: float = option(3e-4, lo=0, lo_open=True, help="stage loc's learning rate (FC_loc alone)")
    loc_passes: int = option(100, lo=1, hi=10_000, help="stage loc: passes through each round's moves")
    lr_schedule: str = option("constant", choices=SCHEDULES, help=(
        "each stage's learning rate: constant or cosine down to 1 %"))
    view_gradient: str = option("surface", choices=GRADIENT_RULES, help="depth-layer backward rule")
    lr_view_scale: float = option(1.0, lo=0, help=(
        "FC_loc's learning rate relative to the rest in the joint stage"))
    step_weighting: str = option("uniform", choices=STEP_WEIGHTINGS, help=(
        "joint loss over the steps: uniform (the paper) or early (1/t)"))
    initial_step: list | None = option(None, kind=list, optional=True, length=(2, 2),
                                       items=Check(float), metavar=("DTHETA", "DPHI"), help=(
                                           "radians: the view head's increment when the joint stage "
                                           "starts (FC_loc's bias; default 0 0)"))
    gradient_reduction: str = option("mean", choices=("mean", "sum"),
                                     help="how per-pixel view gradients are reduced")
    eval_shapes: int = option(200, lo=0, help="validation shapes scored per epoch (metrics.csv; 0: none)")
    eval_every: int = option(1, lo=1, help=(
        "score the validation shapes every N epochs of a stage and at its last (metrics.csv; "
        "the epochs between get blank cells). Nothing trained reads them: only the clock moves"))
    checkpoint_every: int = option(50, lo=1, help="write last.pt every N batches")
    seed: int = option(0, lo=0, hi=SEED_MAX, help="seed of every random choice")
    device: str = option("cpu", pattern=r"cpu|cuda(:[0-9]+)?", text="cpu, cuda or cuda:N",
                         help="cpu, cuda or cuda:N")
    resume: bool = option(False, help="continue from OUT/last.pt")
    prefetch: bool = option(False, help=(
        "make each batch's cameras and renders on a thread while the network works on the batch "
        "before (the same batches, bit for bit; it pays where a core would idle)"))
    render_process: bool = option(False, help=(
        "make each batch's cameras and renders on a process of its own while the network works "
        "on the batch before (the same batches, bit for bit; one process only, not under torchrun)"))
    teacher_precision: str = option("auto", choices=PRECISIONS, help=(
        "imitation: the precision of the teacher's pass over the 50 candidate views (no gradient "
        "flows there, it only ranks them): auto is bfloat16 where the hardware runs it fast "
        "(AVX-512 CPUs, GPUs), float32 elsewhere"))
    teacher_share: float = option(1.0, lo=0, lo_open=True, hi=1, help=(
        "imitation: the share of the candidates within reach the teacher ranks, a random set "
        "drawn per batch (never fewer than steps + 1): FC_view learns the best of them, for that "
        "share of the teacher's encoder work; 1 = every candidate"))
    max_shapes: int = option(0, lo=0, help=(
        "train on a seeded subset of this many shapes, each class in it (0: all)"))
    yaw: bool = option(False, help=AUGMENT + (
        "turn every training object by a random yaw about z (for an object frame of unknown "
        "heading)"))
    yaw_range: float = option(180.0, lo=0, hi=180, lo_open=True, help=(
        "degrees: --yaw turns objects within +-this (180, the whole turn)"))
    frame_error: float = option(0.0, lo=0, hi=0.5, hi_open=True, help=AUGMENT + (
        "object frame off by up to this fraction of the object's size, in centre and in size (a "
        "detector's error; 0.25 in the shipped preset)"))
    floor_cut: float = option(0.0, lo=0, hi=0.5, hi_open=True, help=AUGMENT + (
        "cut away up to this fraction of the object's bottom"))
    dropout: float = option(0.0, lo=0, hi=0.5, hi_open=True, help=AUGMENT + (
        "up to this fraction of each image's pixels, and as many of its depth-edge pixels, "
        "missing"))
    steep_dropout: float = option(0.0, lo=0, hi=1, help=AUGMENT + (
        "the chance that an image loses its pixels beside jumps steeper than a surface seen "
        "70-85 degrees from face-on, as a depth camera's flying-pixel filter removes them"))
    mirror: float = option(0.0, lo=0, hi=1, help=AUGMENT + (
        "the chance a training object is mirrored left to right"))
    stretch: float = option(0.0, lo=0, hi=0.5, hi_open=True, help=AUGMENT + (
        "each axis of a training object scaled by a factor within [1/(1+S), 1+S], log-uniform"))
    # the model's options (num_classes comes from the dataset); a preset's `model:` mapping
    model: ModelConfig = nested(ModelConfig)

    def __post_init__(self):
        if isinstance(self.model, Mapping) and "num_classes" in self.model:
            raise InputError("model.num_classes comes from the dataset's classes: leave it out")
        validate(self)  # min above max is refused now (ViewLimits)
        if self.policy == "imitation" and not self.model.candidates:
            raise InputError("policy imitation needs a view-scoring head: set model.candidates "
                             "(--candidates 50)")
        if self.outliers and self.joint_epochs and self.policy != "imitation":
            raise InputError(f"outliers: the joint stage's outlier episodes are imitation's (random "
                             f"candidate views), not policy {self.policy}'s: use policy imitation or outliers 0")
        if self.real_outliers_root and not self.real_outliers:
            raise InputError("real_outliers_root names the real unknowns' folder for real_outliers, which is 0: "
                             "set real_outliers (a share of each batch's outliers) or leave the root out")
        if self.real_outliers and self.dataset not in ("modelnet", "procedural"):
            raise InputError(f"real_outliers: the real unknowns are of no ModelNet10 class, not of no {self.dataset} "
                             f"class (some are shelves and cabinets): use them with dataset modelnet or procedural "
                             f"(ModelNet10's ten classes)")
        if self.real_outliers and not (self.outliers and self.real_outliers_root):
            raise InputError("real_outliers: needs outliers above 0 and real_outliers_root, the folder "
                             "tools/fetch_real_unknowns.py rebuilt the real unknowns in")
        if self.outlier_margins is not None:
            known, unknown = self.outlier_margins
            if not self.outliers:
                raise InputError("outlier_margins: set the weight of the outlier loss they shape (outliers above 0) "
                                 "or leave them out")
            if not known < unknown:
                raise InputError(f"outlier_margins: the known objects' free energy bound {known:g} must lie below "
                                 f"the unknown ones' {unknown:g}")
        if self.near_outliers + self.real_outliers > 1:
            raise InputError(f"near_outliers {self.near_outliers:g} and real_outliers {self.real_outliers:g} are "
                             f"shares of one batch's unknown objects: together at most 1")
        if self.teacher_share < 1 and self.policy != "imitation":
            raise InputError(f"teacher_share: only imitation has a teacher, not policy {self.policy}: "
                             f"leave teacher_share at 1")
        if self.band_share and self.limits.min_elevation >= 0:
            raise InputError(f"band_share: min_elevation {self.limits.min_elevation:g} keeps every "
                             f"view above the object's centre already: leave band_share at 0")
        if self.initial_step is not None:  # refuse it now, not after pre-training
            initial_step_bias(self.initial_step, self.model.max_step)
        if self.stage == "loc" and not self.resume:
            raise InputError("stage loc fits FC_loc of a trained model: run it with --resume on the "
                             "run's folder (--out), or train with --stage all")
        if self.model.loc_hidden and not self.loc_epochs:
            raise InputError("model.loc_hidden is FC_loc's hidden layer, which stage loc trains: set loc_epochs too")
        if self.loc_epochs and (self.policy != "imitation" or not self.model.loc_hidden):
            raise InputError("stage loc (loc_epochs) fits FC_loc to FC_view's choices: it needs "
                             "policy imitation and model.loc_hidden (its hidden layer's width)")
        if not any(getattr(self, f"{s}_epochs") for s in (STAGES if self.stage == "all" else (self.stage,))):
            raise InputError(f"nothing to train: stage {self.stage} with pretrain_epochs {self.pretrain_epochs}, "
                             f"joint_epochs {self.joint_epochs} and loc_epochs {self.loc_epochs}")

    def augment(self, camera=None) -> Augment:
        """The augmentation these options ask for, on images of `camera` (a CameraConfig)."""
        return Augment(self.yaw, self.frame_error, self.floor_cut, self.dropout, self.yaw_range,
                       mirror=self.mirror, steep=self.steep_dropout, stretch=self.stretch,
                       view_camera=camera)

    def to_dict(self) -> dict:
        """The options as a preset holds them (what a checkpoint's `config` is)."""
        values = as_dict(self)
        values["model"].pop("num_classes")  # the dataset's, in the checkpoint's model_args
        return values


def preset_config(preset=None, flags=None) -> TrainConfig:
    """The run's TrainConfig: the YAML `preset`, then the `flags` set ({option name: value}, the
    model's options among them; None and False are unset)."""
    values = {}
    if preset is not None:
        values = load_yaml(preset, "--config")
        try:
            values = check_mapping(TrainConfig, values)
        except InputError as e:
            raise InputError(f"--config {preset}: {e}") from None
    given = group(TrainConfig, {k: v for k, v in (flags or {}).items() if v is not None and v is not False})
    for key, value in given.items():
        values[key] = {**values[key], **value} if isinstance(values.get(key), Mapping) else value
    return TrainConfig(**values)
