# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""What the object's size says about its class: a cue the depth images cannot carry.

The model sees each object scaled into a unit box, so a night stand and a dresser, alike but for
size, look alike to it. A robot knows the size: its detector's box gives `object_size`, the
longest edge in metres. The prior is, per class, a log-normal over that edge, fitted on the
training split (median and scaled median absolute deviation of the log sizes: a few models drawn
in other units do not widen it), mixed with a uniform chance `outlier` over the sizes seen (an
odd unit, a bad box), so a size unlike its class's lowers that class but never rules it out.
The episode answers p(class | images) x p(size | class)^weight, renormalised; `weight` and
`outlier` are chosen on the validation split (benchmarks/size_prior_weight.py).
"""
from __future__ import annotations

import math
import warnings
from dataclasses import dataclass

import numpy as np
import torch

from active_recognition.argument_checks import InputError

MIN_SCALE = 0.05  # log units: a class whose sizes all agree still allows about 5 % either way
KEYS = ("log_median", "log_scale", "log_lo", "log_hi", "weight", "outlier")


@dataclass
class SizePrior:
    log_median: list   # per class, log metres
    log_scale: list    # per class, > 0
    log_lo: float      # the log sizes the outliers spread over
    log_hi: float
    weight: float = 0.25  # both chosen on ModelNet10's validation split
    outlier: float = 0.05  # (docs/results/modelnet10/size_prior.json)

    def log_normal(self, size):
        """(B, C) each class's log-normal log-density of sizes (B,) in metres, the outlier chance
        left out; InputError for a size that is not a positive number."""
        size = torch.as_tensor(size, dtype=torch.float64).reshape(-1)
        if not (torch.isfinite(size).all() and (size > 0).all()):
            raise InputError(f"object size must be a positive number of metres, got {size.tolist()}")
        sd = torch.tensor(self.log_scale, dtype=torch.float64)
        z = (size.log()[:, None] - torch.tensor(self.log_median, dtype=torch.float64)) / sd
        return -0.5 * z ** 2 - torch.log(sd * math.sqrt(2 * math.pi))

    def log_likelihood(self, size):
        """(B, C) log p(size | class) for sizes (B,) in metres."""
        normal = self.log_normal(size).exp()
        return torch.log((1 - self.outlier) * normal + self.outlier / (self.log_hi - self.log_lo))

    def surprise(self, size):
        """(B,) how unlike every class's sizes each size (metres) is: -max over the classes of the
        log-normal log-density, the outlier chance left out (the `unknown` answer's size term)."""
        return (-self.log_normal(size).max(-1).values).numpy()

    def apply(self, probs, size):
        """probs (B, C) x p(size | class)^weight, renormalised (sizes (B,) in metres)."""
        log = probs.double().clamp_min(1e-12).log() + self.weight * self.log_likelihood(size)
        return log.softmax(-1).to(probs.dtype)

    def to_dict(self):
        return {k: getattr(self, k) for k in KEYS}

    @classmethod
    def from_dict(cls, value, num_classes, where="size_prior"):
        """A prior from a checkpoint's dict; InputError naming what is wrong with it."""
        if not isinstance(value, dict) or set(value) != set(KEYS):
            raise InputError(f"{where}: expected the keys {', '.join(KEYS)}")
        for k in ("log_median", "log_scale"):
            v = value[k]
            if not (isinstance(v, list) and len(v) == num_classes
                    and all(isinstance(x, (int, float)) and math.isfinite(x) for x in v)):
                raise InputError(f"{where}: {k} must be {num_classes} finite numbers, one a class")
        numbers = [value[k] for k in KEYS[2:]]
        if not all(isinstance(x, (int, float)) and math.isfinite(x) for x in numbers):
            raise InputError(f"{where}: log_lo, log_hi, weight and outlier must be finite numbers")
        if min(value["log_scale"]) <= 0 or value["log_hi"] <= value["log_lo"]:
            raise InputError(f"{where}: log_scale must be positive and log_hi above log_lo")
        if not (0 <= value["weight"] <= 10 and 0 < value["outlier"] < 1):
            raise InputError(f"{where}: weight must lie in [0, 10] and outlier in (0, 1)")
        return cls(**{k: value[k] if k in KEYS[:2] else float(value[k]) for k in KEYS})


def fit(sizes, labels, num_classes, weight=SizePrior.weight, outlier=SizePrior.outlier) -> SizePrior:
    """The prior of objects whose longest box edges (metres) are `sizes`, classes `labels`;
    InputError when a class has fewer than 2 sizes or a size is not a positive number."""
    sizes, labels = np.asarray(sizes, dtype=np.float64), np.asarray(labels)
    if len(sizes) != len(labels) or not (np.isfinite(sizes).all() and (sizes > 0).all()):
        raise InputError("the size prior needs one positive size (metres) per object")
    logs = np.log(sizes)
    median, scale = [], []
    for c in range(num_classes):
        mine = logs[labels == c]
        if len(mine) < 2:
            raise InputError(f"the size prior needs at least 2 sizes of each class; class {c} has "
                             f"{len(mine)}")
        m = float(np.median(mine))
        median.append(m)
        scale.append(max(MIN_SCALE, 1.4826 * float(np.median(np.abs(mine - m)))))
    # the outliers spread over the sizes seen and a factor e beyond either end
    return SizePrior(median, scale, float(logs.min()) - 1, float(logs.max()) + 1, float(weight),
                     float(outlier))


def entry(shapes, num_classes):
    """{'size_prior': dict} fitted on `shapes` (datasets.shapes.Shapes) for a checkpoint, or {}
    where the dataset does not know its objects' sizes."""
    sizes = shapes.sizes(range(len(shapes)))
    if sizes is None:
        return {}
    try:
        return {"size_prior": fit(sizes, shapes.labels, num_classes).to_dict()}
    except InputError as e:  # a handful of training shapes: no prior, the images alone
        warnings.warn(f"no size prior in the checkpoint: {e}")
        return {}
