# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""The learning rate over a training stage: constant (the paper's), or a cosine from the stage's
rate down to FLOOR of it at its last batch, which lets a stage settle into a minimum instead of
ending at the rate it explored with. modelnet10.pt was trained with the cosine
(config/train_modelnet10.yaml); procedural.pt and twins.pt at a constant rate."""
import math

SCHEDULES = ("constant", "cosine")
FLOOR = 0.01


def lr_factor(schedule, batch, batches):
    """The learning rate of batch `batch` (0-based) of a stage of `batches`, over the stage's own."""
    if schedule == "constant" or batches <= 1:
        return 1.0
    return FLOOR + (1 - FLOOR) * 0.5 * (1 + math.cos(math.pi * batch / (batches - 1)))


def set_lr(opt, factor):
    """Every parameter group of `opt` at `factor` x its rate when the stage began ('initial_lr',
    kept in the optimizer's state so a resumed stage goes on from where it was)."""
    for group in opt.param_groups:
        group.setdefault("initial_lr", group["lr"])
        group["lr"] = group["initial_lr"] * factor
