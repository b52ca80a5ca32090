# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""Several trained networks of the same options read the same images, as one model.

An `Ensemble` is a drop-in `RecurrentAttention`: its state is its members' states side by side,
its logits the mean of theirs, its view scores (FC_view) the mean of its members'
log-probabilities over the candidates, its FC_loc the first member's. Members keep their own
weights: a network trained without outliers (the better classifier) beside one trained with them
(the better judge of unknown objects). `judges` names the members whose averaged logits give the
energy the `unknown` answer reads (`judge_logits`; default every member): the judge need not be
the classifier. Nothing is trained here; training/write_ensemble.py writes an ensemble's checkpoint (every
member's weights under 'model', their number under 'members', the judges under 'judges'), and
its `unknown` answer is fitted on the ensemble itself (unknown/fit.py).
"""
from __future__ import annotations

from dataclasses import dataclass

import torch
from torch import nn

from active_recognition.argument_checks import Check, InputError, option
from active_recognition.model.network import ModelConfig, RecurrentAttention

MAX_MEMBERS = 8


@dataclass
class EnsembleConfig(ModelConfig):
    """A member's options, and how many members: the state is theirs side by side."""

    members: int = option(2, lo=2, hi=MAX_MEMBERS, flag=False, help="networks in the ensemble")
    judges: list = option([], flag=False, items=Check(int, lo=0, hi=MAX_MEMBERS - 1), length=(0, MAX_MEMBERS),
                          help="the members whose logits the unknown score reads (empty: every one)")

    def __post_init__(self):
        super().__post_init__()
        if any(j >= self.members for j in self.judges) or len(set(self.judges)) != len(self.judges):
            raise InputError(f"judges {self.judges}: distinct member indices from 0 to {self.members - 1} expected")

    @property
    def member_state(self):
        return super().state_size

    @property
    def state_size(self):
        return self.members * self.member_state

    def member(self):
        """A plain ModelConfig: the options of one member."""
        args = self.to_dict()
        args.pop("members"), args.pop("judges")
        return ModelConfig(**args)


class Ensemble(nn.Module):
    def __init__(self, config: EnsembleConfig):
        super().__init__()
        self.config = config
        self.size_prior = None
        self.open_set = None
        self.members = nn.ModuleList(RecurrentAttention(config.member()) for _ in range(config.members))

    def parts(self, state):
        """A state (B, members x S) as each member's (B, S)."""
        return state.split(self.config.member_state, -1)

    def init_hidden(self, batch, device=None):
        return torch.zeros(batch, self.config.state_size, device=device)

    def features(self, depth):
        """Every member's image features side by side (B, members x F)."""
        return torch.cat([m.features(depth) for m in self.members], -1)

    def advance(self, features, state, view=None):
        size = self.config.feature_size
        return torch.cat([m.advance(f, s, view) for m, f, s in
                          zip(self.members, features.split(size, -1), self.parts(state))], -1)

    def classify(self, state):
        """The mean of the members' logits."""
        return torch.stack([m.classify(s) for m, s in zip(self.members, self.parts(state))]).mean(0)

    def judge_logits(self, state):
        """The logits the unknown score reads: the mean of the judges' (config.judges)."""
        parts = self.parts(state)
        judges = self.config.judges or range(self.config.members)
        return torch.stack([self.members[j].classify(parts[j]) for j in judges]).mean(0)

    def increment(self, state):
        """The first member's FC_loc."""
        return self.members[0].increment(self.parts(state)[0])

    def score_views(self, state):
        """The mean of the members' log-probabilities over FC_view's candidates."""
        return torch.stack([m.score_views(s).log_softmax(-1)
                            for m, s in zip(self.members, self.parts(state))]).mean(0)

    # one step, and the shape classifier alone, composed exactly as a single network's are
    forward = RecurrentAttention.forward
    classify_image = RecurrentAttention.classify_image
