# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""When the recognizer answers `unknown`, and when a confident answer waits: the decision.

`UnknownDecision` is what runtime/active_recognizer.ActiveRecognizer inherits for it. Each view
is scored as it is classified (`doubt`: its energy, and its prototype score where the checkpoint
carries class means, thresholds.py); the episode's answer is `unknown` where the mean score of
its views is above the threshold in force for that many views (the checkpoint's own, or the
node's unknown_threshold / unknown_energy), and while it is, a confident answer waits
(hold_unknown). The scores are in scores.py; the thresholds are fitted by fit.py.

It reads, of the recognizer: model (its open_set entry), sensing (SensingConfig), and the
per-view lists energies and prototypes that reset() empties.
"""
from __future__ import annotations

import math

import numpy as np
import torch

from active_recognition.unknown.scores import energy, judged, own_thresholds, prototype_at, step_thresholds


class UnknownDecision:
    """The unknown answer's half of the recognizer (a mixin: ActiveRecognizer)."""

    def doubt(self, episode, logits):
        """Episode.doubt: scores the view (its energy, an ensemble's of its judges' logits; its prototype score where
        the checkpoint carries class means) and says if a confident answer waits (hold_unknown: it looks unknown)."""
        logits = judged(self.model, logits, episode.hidden[:1])
        self.energies.append(float(energy(logits[0].detach().cpu().numpy())))
        if self.model.open_set is not None:
            self.prototypes.append(float(prototype_at(episode.hidden[:1].detach().cpu().numpy(),
                                                      self.model.open_set["means"].numpy(), episode.steps - 1)[0]))
        return torch.tensor([self.sensing.hold_unknown and self.looks_unknown()])

    def unknown(self):
        """Whether the evidence so far says the object is of none of the classes: the mean energy
        of its views above sensing.unknown_energy (never where that is 0), or looks_unknown (the
        checkpoint's own score and thresholds, or prototype_mean above sensing.unknown_threshold)."""
        threshold = self.sensing.unknown_energy
        if threshold != 0 and self.energies and float(np.mean(self.energies)) > threshold:
            return True
        return self.looks_unknown()

    def looks_unknown(self):
        """Whether the mean score of the views so far (open_set_scores) is above the threshold in
        force at this step."""
        scores = self.open_set_scores()
        return scores != [] and float(np.mean(scores)) > self.open_set_threshold()

    def open_set_scores(self):
        """The per-view scores the unknown answer reads: their energies where the checkpoint's
        open_set score is energy_mean (and no unknown_threshold overrides it), else prototypes."""
        own = self.sensing.unknown_threshold < 0 and self.model.open_set is not None
        return self.energies if own and self.model.open_set["score"] == "energy_mean" else self.prototypes

    def open_set_threshold(self):
        """The threshold in force after the views scored so far (inf: none): the checkpoint's for that many
        views on its own score, for this size (scores.own_thresholds), or sensing.unknown_threshold's."""
        chosen = self.sensing.unknown_threshold
        if chosen == 0 or self.model.open_set is None:
            return math.inf
        if chosen > 0:
            return chosen
        own = own_thresholds(self.model, self.sensing.object_size if self.sensing.use_size else None)
        return float(step_thresholds(own, max(len(self.open_set_scores()), 1))[-1])
