# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""The recurrent 3D attentional network: Conv2D encoder, ReLU RNN cell, FC_class and FC_loc.

SC (shape classifier) = encoder + cell (from a zero state) + FC_class; 3D-STN = encoder + FC_loc.
Two options beyond the paper: `view_input` feeds the current view (the camera's unit position)
to the RNN beside the image features, as MV-RNN does, so the state knows where each image was
taken; `candidates` > 0 adds FC_view, a head that scores that many evenly spread candidate views
(geometry.fibonacci_views) from h_t, trained by imitating a label-aware teacher (train --policy imitation).
"""
from __future__ import annotations

import math
import warnings
from dataclasses import asdict, dataclass

import torch
from torch import nn

from active_recognition.argument_checks import InputError, option, validate
from active_recognition.sensing.geometry import unit_position

ENCODERS = ("compact", "wide", "alexnet")
READOUTS = ("last", "mean", "mean+mirror")
INPUT_SIZE = {"compact": 64, "wide": 64, "alexnet": 227}
READOUT_HELP = ("the answer after t views: FC_class on the last state (last, the paper), the mean of "
                "every step's class probabilities (mean), or that mean with each step's averaged "
                "with its mirror image's (mean+mirror)")


@dataclass
class ModelConfig:
    num_classes: int = option(10, lo=2, hi=100_000, flag=False, help="classes (the dataset's)")
    # compact (64x64, CPU), wide (64x64, twice the channels, batch-normalised) or alexnet (227x227)
    encoder: str = option("compact", choices=ENCODERS, help="Conv2D encoder")
    feature_size: int = option(256, lo=1, hi=8192, flag=False, help="image features e_t")
    hidden_size: int = option(256, lo=1, hi=8192, help="RNN hidden size (h_t; 256 the paper's best)")
    max_step: float = option(0.8, lo=0, hi=math.pi, lo_open=True,
                             help="view increment bound |dtheta|, |dphi|, radians")
    radius: float = option(1.0, lo=0, hi=100, lo_open=True, help="viewing-sphere radius R")
    view_input: bool = option(False, help="feed the current view to the RNN (MV-RNN style)")
    candidates: int = option(0, lo=0, hi=10_000, help=(
        "size of FC_view, the head scoring candidate views (imitation; 0 = none)"))
    # the state the heads read: the RNN's h_t (the paper), or h_t beside the element-wise maximum
    # of the image features seen so far (max: a view's evidence is never forgotten, as in MVCNN's
    # view pooling, so more views cannot hide what one view showed)
    memory: str = option("rnn", choices=("rnn", "rnn+max"), help=(
        "the state the heads read: the RNN's (the paper), or beside it the running maximum of the "
        "image features seen (rnn+max)"))
    # the answer after t views: FC_class on the last state (last, the paper), or the mean of the
    # class probabilities of every step so far (mean: each view's answer counts, so a late view
    # that misleads cannot overturn what the earlier ones agreed on). Training reads each step's
    # own logits either way; the readout is what an episode answers and stops on. mean+mirror:
    # each step's probabilities are averaged with those of its mirror image, the image flipped
    # left to right read as the view (theta, pi - phi) of the object mirrored x -> -x, carried in
    # an RNN state of its own (test-time augmentation for a model trained with mirrored shapes,
    # in eval mode only: training reads each step's own logits; twice the encoder's work a frame)
    readout: str = option("last", choices=READOUTS, help=READOUT_HELP)
    # > 0: FC_loc is the paper's single layer plus a ReLU layer of this width beside it, its output
    # layer zero at first, so the increment is the single layer's until training stage loc fits
    # both (one linear layer cannot follow FC_view's choice, a jump that depends on the view and
    # the state); from stage loc on, a step reaches max_step + loc_step (rad) a component
    loc_hidden: int = option(0, lo=0, hi=8192, help=(
        "width of FC_loc's hidden layer, beside the paper's single layer (0: none)"))
    loc_step: float = option(0.8, lo=0, hi=math.pi, lo_open=True, help=(
        "with --loc-hidden: from stage loc on a step reaches max_step + this (rad)"))

    def __post_init__(self):
        validate(self)

    @property
    def state_size(self):
        return self.hidden_size + (self.feature_size if self.memory == "rnn+max" else 0)

    @property
    def loc_bound(self):
        """The largest |dtheta|, |dphi| FC_loc can ask for once stage loc fitted it (rad)."""
        return self.max_step + (self.loc_step if self.loc_hidden else 0.0)

    @property
    def image_size(self):
        return INPUT_SIZE[self.encoder]

    def to_dict(self):
        return asdict(self)


def compact_encoder(feature_size):
    return nn.Sequential(                                      # (B, 1, 64, 64)
        nn.Conv2d(1, 16, 5, stride=2, padding=2), nn.ReLU(),   # (B, 16, 32, 32)
        nn.Conv2d(16, 32, 3, stride=2, padding=1), nn.ReLU(),  # (B, 32, 16, 16)
        nn.Conv2d(32, 64, 3, stride=2, padding=1), nn.ReLU(),  # (B, 64, 8, 8)
        nn.Conv2d(64, 64, 3, stride=2, padding=1), nn.ReLU(),  # (B, 64, 4, 4)
        nn.Flatten(), nn.Linear(64 * 16, feature_size), nn.ReLU())


def wide_encoder(feature_size):
    """compact's layout with twice the channels, each convolution batch-normalised: ModelNet10's
    real shapes underfit the compact encoder (its training accuracy stays at its validation's).
    Each ReLU works in place on its batch norm's output, which nothing else keeps: the same
    numbers, a fifth less time in the encoder on a CPU (no pass to allocate and fill a copy)."""
    def block(cin, cout, k):
        return [nn.Conv2d(cin, cout, k, stride=2, padding=k // 2, bias=False), nn.BatchNorm2d(cout),
                nn.ReLU(inplace=True)]
    return nn.Sequential(*block(1, 32, 5), *block(32, 64, 3), *block(64, 128, 3),  # (B, 128, 8, 8)
                         *block(128, 128, 3), nn.Flatten(),                        # (B, 128, 4, 4)
                         nn.Linear(128 * 16, feature_size), nn.ReLU())


def alexnet_encoder(feature_size):
    return nn.Sequential(                                               # (B, 1, 227, 227)
        nn.Conv2d(1, 96, 11, stride=4), nn.ReLU(), nn.MaxPool2d(3, 2),  # (B, 96, 27, 27)
        nn.Conv2d(96, 256, 5, padding=2), nn.ReLU(), nn.MaxPool2d(3, 2),  # (B, 256, 13, 13)
        nn.Conv2d(256, 384, 3, padding=1), nn.ReLU(),
        nn.Conv2d(384, 384, 3, padding=1), nn.ReLU(),
        nn.Conv2d(384, 256, 3, padding=1), nn.ReLU(), nn.MaxPool2d(3, 2),  # (B, 256, 6, 6)
        nn.Flatten(), nn.Dropout(0.5), nn.Linear(256 * 36, 4096), nn.ReLU(),
        nn.Dropout(0.5), nn.Linear(4096, feature_size), nn.ReLU())


class RecurrentAttention(nn.Module):
    def __init__(self, config: ModelConfig):
        super().__init__()
        self.config = config
        self.size_prior = None  # size_prior.SizePrior a checkpoint may carry: episodes answer with it
        # a checkpoint's open_set entry (unknown/thresholds.checked_open_set): the recognizer's unknown answer
        self.open_set = None
        build = {"compact": compact_encoder, "wide": wide_encoder, "alexnet": alexnet_encoder}[config.encoder]
        self.encoder = build(config.feature_size)
        inputs = config.feature_size + (3 if config.view_input else 0)
        self.cell = nn.RNNCell(inputs, config.hidden_size, nonlinearity="relu")
        state = config.state_size
        self.classify = nn.Linear(state, config.num_classes)   # FC_class
        self.locate = nn.Linear(state, 2)                      # FC_loc
        nn.init.normal_(self.locate.weight, std=0.01)
        nn.init.zeros_(self.locate.bias)
        if config.candidates:
            self.score_views = nn.Linear(state, config.candidates)  # FC_view
        if config.loc_hidden:  # built last, so every other layer starts as it would without it
            self.locate_mlp = nn.Sequential(nn.Linear(state, config.loc_hidden), nn.ReLU(),
                                            nn.Linear(config.loc_hidden, 2))
            nn.init.zeros_(self.locate_mlp[-1].weight)
            nn.init.zeros_(self.locate_mlp[-1].bias)
            self.register_buffer("loc_fitted", torch.zeros(()))  # 1 once stage loc began

    def init_hidden(self, batch, device=None):
        """The state before any view (B, state_size): zeros."""
        return torch.zeros(batch, self.config.state_size, device=device)

    def advance(self, features, state, view=None):
        """The state after one more image: the RNN cell on e_t (and the view), and with memory
        rnn+max the running maximum of the features beside it."""
        h = self.cell(self.cell_input(features, view), state[:, :self.config.hidden_size])
        if self.config.memory == "rnn":
            return h
        return torch.cat([h, torch.maximum(state[:, self.config.hidden_size:], features)], -1)

    def features(self, depth):
        """Normalised depth (B, H, W) in [0, 255] -> e_t (B, feature_size)."""
        size = self.config.image_size
        assert depth.shape[-2:] == (size, size), f"expected {size}x{size} depth, got {tuple(depth.shape)}"
        return self.encoder(1.0 - depth.unsqueeze(1) / 255.0)  # background 0, near surfaces ~1

    def cell_input(self, features, view=None):
        """The RNN's input: e_t, with the view's unit camera position (B, 3) when view_input."""
        if not self.config.view_input:
            return features
        if view is None:
            raise ValueError("this model reads the current view (view_input): pass view (B, 2)")
        position = unit_position(view.detach().to(features.dtype))
        return torch.cat([features, position.expand(len(features), 3)], -1)

    def forward(self, depth, hidden, view=None):
        """One step from the image(s) taken at view (B, 2): (logits (B, C), view increment (B, 2),
        new hidden (B, hidden_size))."""
        hidden = self.advance(self.features(depth), hidden, view)
        delta = self.increment(hidden)
        return self.classify(hidden), delta, hidden

    def increment(self, hidden):
        """The view increment FC_loc asks for from a state: (dtheta, dphi) (B, 2), each within
        +-max_step (+-loc_bound with the hidden layer)."""
        if not self.config.loc_hidden:
            return self.config.max_step * torch.tanh(self.locate(hidden))
        bound = self.config.max_step + self.config.loc_step * self.loc_fitted
        return bound * torch.tanh(self.locate(hidden) + self.locate_mlp(hidden))

    def classify_image(self, depth, view=None):
        """The shape classifier alone: logits from one image, from a zero state."""
        return self.classify(self.advance(self.features(depth), self.init_hidden(len(depth), depth.device),
                                          view))


def single_step(model: RecurrentAttention):
    """`model`'s forward for one object at a time (B = 1) at inference, as a robot runs it: traced
    by TorchScript with the weights frozen in, each convolution fused with its batch norm and
    prepacked (torch.jit.optimize_for_inference). The same numbers as the module's own forward to
    float precision, in 0.6-0.75 of its time on a CPU (benchmarks/ros_latency.py). The module
    itself where tracing fails."""
    size = model.config.image_size
    example = (torch.zeros(1, size, size), model.init_hidden(1), torch.zeros(1, 2))
    try:
        with torch.no_grad(), warnings.catch_warnings():
            warnings.simplefilter("ignore")  # the tracer's notes on the shape assert, B = 1 baked in
            return torch.jit.optimize_for_inference(torch.jit.freeze(
                torch.jit.trace(model.eval(), example, check_trace=False)))
    except (RuntimeError, TypeError) as e:  # an operator TorchScript cannot trace
        warnings.warn(f"the model could not be traced ({e}); each step runs the module itself")
        return model


def initial_step_bias(step, bound):
    """FC_loc's bias that makes the untrained view head walk `step`: atanh(step / bound)."""
    ratio = torch.as_tensor([float(v) for v in step]) / bound
    if ratio.abs().max() >= 1:
        raise InputError(f"initial step {list(step)} must lie inside the increment bound "
                         f"max_step = {bound}")
    return torch.atanh(ratio)


def set_initial_step(model, step):
    """Make the untrained view head walk a fixed increment."""
    with torch.no_grad():
        model.locate.bias.copy_(initial_step_bias(step, model.config.max_step))
