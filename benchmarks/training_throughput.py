# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""Joint-training throughput: 10-step episodes at 64x64, batch 32 as trained, on the procedural
benchmark; where the time goes (rendering incl. the depth layer's backward, network forward,
network backward, optimiser). Median over batches; last line is JSON.

With --dataset modelnet (or --config): steps of a training recipe (config/train_modelnet10.yaml
by default), pre-training and joint, through the trainer's own step (step_breakdown.py), each
step's shares (rendering, the imitation's candidates included; augmentation; the encoder forward
and backward; the recurrent part and heads; the optimiser; data handling), and the network's
FLOP rate against torch.matmul's here."""
import argparse
import os
import tempfile
import time
from pathlib import Path

import numpy as np
import torch
from common import emit, one_line_errors
from step_breakdown import Clock, SHARES, breakdown, instrument, matmul_flops

from active_recognition.datasets import default_cache_dir, open_dataset
from active_recognition.datasets.shapes import Shapes
from active_recognition.model.network import ModelConfig, RecurrentAttention
from active_recognition.options.flags_and_parameters import add_flags
from active_recognition.sensing import depth_layer, geometry
from active_recognition.sensing.depth_layer import CameraConfig, GRADIENT_RULES
from active_recognition.training import losses
from active_recognition.training.losses import JointLoss
from active_recognition.training.train import Trainer, joint_loss
from active_recognition.training.train_config import TrainConfig, preset_config

RECIPE = Path(__file__).resolve().parents[1] / "config/train_modelnet10.yaml"

CLOCK = {"render": 0.0}


def timed(fn):
    def wrapper(*args, **kwargs):
        t = time.perf_counter()
        try:
            return fn(*args, **kwargs)
        finally:
            CLOCK["render"] += time.perf_counter() - t
    return wrapper


def sync(device):
    if device.type == "cuda":
        torch.cuda.synchronize(device)


def main():
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--batches", type=int, default=12)
    add_flags(ap, TrainConfig, ["batch_size"])
    ap.add_argument("--rule", default="surface", choices=GRADIENT_RULES)
    add_flags(ap, TrainConfig, ["device"], device={"help": "where the network runs (rendering is on the CPU)"})
    add_flags(ap, TrainConfig, ["dataset", "root"], dataset={
        "help": "procedural: 10-step episodes of the default model; another (with --root): a recipe's steps"})
    ap.add_argument("--config", default=None, help=f"the recipe timed (default with a --dataset other "
                                                   f"than procedural: {RECIPE.name})")
    ap.add_argument("--steps", type=int, default=6, help="recipe: pre-training steps timed")
    ap.add_argument("--joint-steps", type=int, default=3, help="recipe: joint steps timed")
    args = ap.parse_args()
    if args.config or args.dataset != "procedural":
        with one_line_errors(ap):
            return recipe(args)
    # time every render and every depth-layer backward (the Jacobian), wherever they are called
    depth_layer.trace_all = timed(depth_layer.trace_all)
    depth_layer.DepthCamera.render_hits = timed(depth_layer.DepthCamera.render_hits)
    depth_layer._RenderViews.backward = staticmethod(timed(depth_layer._RenderViews.backward))
    torch.manual_seed(0)
    shapes = Shapes(open_dataset("procedural", split="train", cache_dir=default_cache_dir()),
                    CameraConfig(64, 64))
    device = torch.device(args.device)
    model = RecurrentAttention(ModelConfig()).to(device)
    net = JointLoss(model, steps=10, rule=args.rule, reduction="mean")
    opt = torch.optim.Adam(model.parameters(), 3e-4)
    rng = np.random.default_rng(0)
    rows = []
    for b in range(args.batches + 2):
        idx = rng.permutation(len(shapes))[:args.batch_size]
        cams = shapes.cameras(idx)
        views = geometry.fibonacci_views(50)[rng.integers(0, 50, len(idx))]
        y = torch.as_tensor(shapes.labels[idx], device=device)
        CLOCK["render"] = 0.0
        t0 = time.perf_counter()
        loss, _ = net(cams, views, y)
        sync(device)
        t1 = time.perf_counter()
        render_fwd = CLOCK["render"]
        opt.zero_grad()
        loss.backward()
        sync(device)
        t2 = time.perf_counter()
        opt.step()
        sync(device)
        t3 = time.perf_counter()
        render_bwd = CLOCK["render"] - render_fwd
        if b >= 2:  # warm-up batches build the cameras' embree scenes
            rows.append((t3 - t0, render_fwd + render_bwd, t1 - t0 - render_fwd,
                         t2 - t1 - render_bwd, t3 - t2))
    total, render, fwd, bwd, step = np.median(np.array(rows), axis=0)
    eps = args.batch_size / total
    print(f"{eps:.1f} episodes/s: batch {1e3 * total:.0f} ms = render {1e3 * render:.0f} + "
          f"forward {1e3 * fwd:.0f} + backward {1e3 * bwd:.0f} + optimiser {1e3 * step:.0f} ms")
    emit({"episodes_per_s": eps, "batch_size": args.batch_size, "steps": 10, "image": 64,
          "share_render": render / total, "share_forward": fwd / total,
          "share_backward": bwd / total, "share_optimizer": step / total,
          "torch_threads": torch.get_num_threads(), "device": args.device})


def recipe(args):
    """Steps of a training recipe, pre-training and joint: their time and its shares."""
    device = torch.device(args.device)
    clock = Clock(device)
    load, early = os.getloadavg()[0], matmul_flops(device)
    with tempfile.TemporaryDirectory() as out:
        cfg = preset_config(args.config or RECIPE, {"dataset": args.dataset, "root": args.root,
                                                    "out": out, "device": args.device})
        instrument(clock)  # first: the trainer keeps bound methods (its corrupt: Augment.images)
        trainer = Trainer(cfg, progress=False)
        result = {"config": str(args.config or RECIPE.name), "dataset": cfg.dataset,
                  "batch_size": cfg.batch_size, "batches_per_epoch": len(trainer.shapes) // cfg.batch_size}
        for stage, steps in (("pretrain", args.steps), ("joint", args.joint_steps)):
            wrapper = (losses.PretrainLoss(trainer.model) if stage == "pretrain"
                       else joint_loss(cfg, trainer.model, trainer.corrupt))
            med, flops, build = breakdown(trainer, stage, wrapper, steps, clock)
            net = med["encoder"] + med["recurrent_heads"]
            result.update({f"{stage}_step_s": med["step"],
                           f"{stage}_epoch_s": med["step"] * result["batches_per_epoch"],
                           **{f"{stage}_share_{k}": med[k] / med["step"] for k in SHARES},
                           f"{stage}_network_gflop_per_step": flops / 1e9,
                           f"{stage}_network_gflops": flops / net / 1e9 if net else 0.0,
                           "scene_build_ms_per_shape": build * 1e3})
            print(f"{stage}: {med['step']:.3f} s a step = " + " + ".join(
                f"{k} {med[k]:.3f}" for k in SHARES) + f"; network {flops / 1e9:.1f} GFLOP")
    peak = max(matmul_flops(device), early)  # before and after the steps: the load may change
    result["matmul_gflops"] = peak / 1e9
    for stage in ("pretrain", "joint"):
        result[f"{stage}_flop_rate_vs_matmul"] = result[f"{stage}_network_gflops"] * 1e9 / peak
        # the recipe's epochs of this stage at the measured step, and its network's work alone
        # at the matmul rate: what no faster kernel can go below without fewer FLOPs
        batches = getattr(cfg, f"{stage}_epochs") * result["batches_per_epoch"]
        result[f"{stage}_minutes"] = batches * result[f"{stage}_step_s"] / 60
        result[f"{stage}_network_minutes_at_matmul"] = (
            batches * result[f"{stage}_network_gflop_per_step"] * 1e9 / peak / 60)
    result.update(torch_threads=torch.get_num_threads(), device=args.device,
                  load_before=load, load_after=os.getloadavg()[0])
    emit(result)


if __name__ == "__main__":
    main()
