# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""A training batch's renders, made ahead on a process of its own (train --render-process).

The thread of `ahead.Ahead` shares the interpreter's lock with the network's step, whose many
small operations hold it; a process holds its own. The worker is a Trainer of the same options
in a spawned process (its own embree scenes, one torch thread): for batch b it makes exactly what
Trainer.inputs makes from the batch's seeded generator (the augmented cameras, then pre-training's
views and images or imitation's candidate renders, clean and as the teacher sees them) and sends
back what is not a camera: the generator after its draws, torch's seed, the views, the images.
The trainer draws the same cameras again from the same seed (Trainer.remade), so the batch is the
one it would make itself, bit for bit, while the worker renders the next one.
"""
from __future__ import annotations

import multiprocessing
import traceback
from dataclasses import replace


def serve(conn, cfg, trainer, joint_loss):
    """The worker: a `trainer` (train.Trainer) of `cfg` answering (stage, epoch, b, idx) with
    batch b's made part; `joint_loss` (train.joint_loss) gives it the joint stage's renders."""
    import torch
    torch.set_num_threads(1)
    try:
        run = trainer(cfg, progress=False)
        loss = joint_loss(cfg, run.model, run.corrupt)
    except Exception:  # noqa: BLE001 (said to the trainer, which raises it)
        conn.send(("error", traceback.format_exc()))
        return
    conn.send(("ready", None))
    while (ask := conn.recv()) is not None:
        stage, epoch, b, idx = ask
        try:
            made = run.inputs(stage, epoch, b, idx, loss if stage == "joint" else None)  # cfg: no outliers
            conn.send(("made", (b, (made.rng, made.torch_seed, made.views, made.depth))))
        except Exception:  # noqa: BLE001
            conn.send(("error", traceback.format_exc()))


class RenderWorker:
    """A spawned process making batches for a `trainer` of options `cfg` (train.Trainer, and
    train.joint_loss: passed in, so this module imports neither): ask(...) starts one, take(b)
    waits for it. One at a time, in the order asked."""

    def __init__(self, cfg, trainer, joint_loss):
        ctx = multiprocessing.get_context("spawn")  # a fork would copy torch's and embree's threads
        self.conn, child = ctx.Pipe()
        worker_cfg = replace(cfg, resume=False, render_process=False, prefetch=False, outliers=0.0,
                             eval_shapes=0)
        self.proc = ctx.Process(target=serve, args=(child, worker_cfg, trainer, joint_loss),
                                daemon=True, name="render-worker")
        self.proc.start()
        child.close()
        self.asked = []
        self.answer("ready")

    def answer(self, expected):
        try:
            kind, value = self.conn.recv()
        except EOFError:
            raise RuntimeError(f"the render worker stopped (exit code {self.proc.exitcode})") from None
        if kind == "error":
            raise RuntimeError(f"the render worker failed:\n{value}")
        if kind != expected:
            raise RuntimeError(f"the render worker answered {kind!r}, expected {expected!r}")
        return value

    def ask(self, stage, epoch, b, idx):
        self.conn.send((stage, epoch, b, list(map(int, idx))))
        self.asked.append(b)

    def take(self, b):
        """Batch b's made part (generator, torch seed, views, images), asked before."""
        if not self.asked or self.asked[0] != b:
            raise RuntimeError(f"batch {b} is not the next one asked of the render worker ({self.asked})")
        got, made = self.answer("made")
        self.asked.pop(0)
        if got != b:
            raise RuntimeError(f"the render worker made batch {got}, expected {b}")
        return made

    def close(self):
        if self.proc.is_alive():
            try:
                self.conn.send(None)
            except OSError:
                pass
            self.proc.join(timeout=10)
        if self.proc.is_alive():
            self.proc.terminate()
        self.conn.close()


class AheadProcess:
    """ahead.Ahead's interface over a RenderWorker: get(b, following) returns batch b's inputs
    (finish(b, made) completes them here) with `following` already asked of the worker."""

    def __init__(self, worker, request, finish):
        self.worker, self.request, self.finish = worker, request, finish

    def get(self, b, following=None):
        for want in (b, following):  # `following` before waiting: it renders while b trains
            if want is not None and want not in self.worker.asked:
                self.worker.ask(*self.request(want))
        return self.finish(b, self.worker.take(b))

    def close(self):
        """Collect what was asked ahead and not used (the epoch's end)."""
        while self.worker.asked:
            self.worker.take(self.worker.asked[0])
