# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""Where a training step of a recipe goes (benchmarks/training_throughput.py --config).

A `Clock` charges each timed function its own time, less that of the timed functions it calls
(rendering inside a loss's forward counts as rendering, not as the network). The encoder's
forward and backward are replayed on a copy of it, on the very inputs the step gave it; the
network's time less the encoder's is the recurrent part and the heads. Everything else in the
step (batches, random numbers, labels, moving tensors, the loss's checks) is data handling."""
import copy
import threading
import time
from collections import defaultdict

import numpy as np
import torch
from torch.utils.flop_counter import FlopCounterMode

from active_recognition.datasets import augment
from active_recognition.sensing import depth_layer
from active_recognition.training import losses

SHARES = ("render", "augment", "encoder", "recurrent_heads", "optimizer", "data")


class Clock:
    """Exclusive seconds per category, counted on the main thread (a pool's workers run inside a
    call the main thread times)."""

    def __init__(self, device):
        self.device, self.totals, self.stack = device, defaultdict(float), []

    def sync(self):
        if self.device.type == "cuda":
            torch.cuda.synchronize(self.device)

    def wrap(self, category, fn):
        def timed(*args, **kwargs):
            if threading.current_thread() is not threading.main_thread():
                return fn(*args, **kwargs)
            self.sync()
            start = time.perf_counter()
            self.stack.append(0.0)
            try:
                return fn(*args, **kwargs)
            finally:
                self.sync()
                took = time.perf_counter() - start
                self.totals[category] += took - self.stack.pop()
                if self.stack:
                    self.stack[-1] += took
        return timed

    def patch(self, owner, name, category):
        setattr(owner, name, self.wrap(category, getattr(owner, name)))


def instrument(clock):
    """Time every render (scene builds, ray casts, depth), augmentation, loss forward, backward."""
    for name in ("trace_all", "render_batch"):
        clock.patch(depth_layer, name, "render")
    for name in ("__init__", "trace", "render_hits"):
        clock.patch(depth_layer.DepthCamera, name, "render")
    clock.patch(augment.Augment, "transform", "augment")
    clock.patch(augment.Augment, "images", "augment")
    for cls in (losses.PretrainLoss, losses.ImitationLoss, losses.JointLoss):
        clock.patch(cls, "forward", "network")
    clock.patch(torch.Tensor, "backward", "network")
    depth_layer._RenderViews.backward = staticmethod(clock.wrap("render", depth_layer._RenderViews.backward))


class EncoderInputs:
    """The encoder's inputs in one step (and whether autograd recorded them), for a replay."""

    def __init__(self, encoder):
        self.encoder, self.inputs = encoder, []
        encoder.register_forward_pre_hook(self.record)

    def record(self, module, args):
        self.inputs.append((args[0].detach().clone(), torch.is_grad_enabled()))

    def replay_s(self, clock):
        """Seconds the recorded inputs take through a copy of the encoder, forward and backward."""
        enc = copy.deepcopy(self.encoder)
        clock.sync()
        start = time.perf_counter()
        for x, grad in self.inputs:
            with torch.set_grad_enabled(grad):
                out = enc(x)
            if grad:
                out.backward(torch.ones_like(out))
        clock.sync()
        self.inputs = []
        return time.perf_counter() - start


def matmul_flops(device, sizes=(512, 1024, 2048), repeat=10):
    """The best FLOP/s torch.matmul reaches here on n x n float32 matrices, n in `sizes` (the
    fastest of `repeat` products each, after a warm-up): the limit the network's rate can near."""
    best = 0.0
    for n in sizes:
        a, b = torch.randn(n, n, device=device), torch.randn(n, n, device=device)
        times = []
        for _ in range(repeat + 2):
            if device.type == "cuda":
                torch.cuda.synchronize(device)
            start = time.perf_counter()
            torch.matmul(a, b)
            if device.type == "cuda":
                torch.cuda.synchronize(device)
            times.append(time.perf_counter() - start)
        best = max(best, 2 * n ** 3 / min(times[2:]))
    return best


def breakdown(trainer, stage, wrapper, steps, clock):
    """Median seconds of a step of `stage` and each share's median, its FLOPs per step, and the
    seconds a shape's scene took to build (once a run: not in the steps)."""
    from active_recognition.training.train import batches
    cfg = trainer.cfg
    opt = trainer.optimizer(stage)
    clock.patch(opt, "step", "optimizer")
    clock.patch(opt, "zero_grad", "optimizer")
    todo = batches(len(trainer.shapes), cfg.batch_size, cfg.seed, stage, 0, 0, 1)
    # every shape's scene is built once, in the first epoch; later epochs, timed here, find it
    start, shapes = time.perf_counter(), np.concatenate(todo[:steps + 1])
    for cam in trainer.shapes.cameras(shapes):
        cam.render(np.array([[1.0, 0.5]]))  # embree builds a scene's hierarchy on its first cast
    build = (time.perf_counter() - start) / len(shapes)
    encoder = EncoderInputs(trainer.model.encoder)
    with FlopCounterMode(display=False) as flops:  # a warm-up step, its FLOPs counted
        trainer.train_step(stage, 0, 1, 0, todo, wrapper, opt)
    encoder.inputs, rows = [], []
    for b in range(1, steps + 1):
        clock.totals.clear()
        start = time.perf_counter()
        trainer.train_step(stage, 0, 1, b, todo, wrapper, opt)
        clock.sync()
        total = time.perf_counter() - start
        t = dict(clock.totals)  # before the replay, whose backward the clock would count
        enc = encoder.replay_s(clock)
        net = t.get("network", 0.0)
        rows.append({"step": total, "render": t.get("render", 0.0), "augment": t.get("augment", 0.0),
                     "encoder": min(enc, net), "recurrent_heads": max(net - enc, 0.0),
                     "optimizer": t.get("optimizer", 0.0),
                     "data": total - sum(t.values())})
    med = {k: float(np.median([r[k] for r in rows])) for k in rows[0]}
    return med, flops.get_total_flops(), build
