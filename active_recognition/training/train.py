# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""Two-stage training: pre-train the shape classifier, then train everything end to end.

Stage "pretrain": depth images of training shapes from random views, cross-entropy.
Stage "joint": episodes of `steps` views from the 50 initial views, cross-entropy at every step,
backpropagation through time; FC_loc learns through the depth layer's view gradient (policy
"learned"), by REINFORCE ("reinforce") or both ("hybrid"); with policy "imitation" FC_view learns
to pick the candidate view its label-aware teacher picks (DAgger: a step follows the teacher or FC_view).
Stage "loc" (imitation, loc_epochs): FC_loc alone learns to move toward FC_view's choice (LocLoss).
Runs in one process or under torchrun (DistributedDataParallel, gloo on CPU, nccl on GPU)."""
from __future__ import annotations

import gc
import sys
import time
from dataclasses import replace
from typing import NamedTuple

import numpy as np
import torch
from torch import nn
from tqdm import tqdm

from active_recognition.argument_checks import InputError, output_dir
from active_recognition.datasets import default_cache_dir, open_splits, subset_with_every_class
from active_recognition.datasets.shapes import Shapes
from active_recognition.model import checkpoint, size_prior
from active_recognition.model.network import RecurrentAttention, set_initial_step
from active_recognition.sensing import depth_layer
from active_recognition.sensing.depth_layer import CameraConfig
from active_recognition.sensing.reach import ViewLimits
from active_recognition.training.devices import (
    distributed, keep_freed_memory, resolve_device, teacher_dtype, training_layout,
)
from active_recognition.training.losses import ImitationLoss, JointLoss, LocLoss, PretrainLoss, ReinforceLoss
from active_recognition.training.lr_schedule import lr_factor, set_lr
from active_recognition.training.outliers import OutlierInputs, Outliers
from active_recognition.training.prefetch import Ahead
from active_recognition.training.render_worker import AheadProcess, RenderWorker
from active_recognition.training.run_metrics import evaluate_accuracy, own_planner, read_metrics, write_metrics
from active_recognition.training.train_config import STAGES, TrainConfig, preset_config  # noqa: F401 (cli, tests)

BAND_STREAM = 7907  # the last key of band_share's draws: apart from the batch's and its outliers' (7919)


def batches(n, batch, seed, stage, epoch, rank, world):
    """This rank's batches of shape indices for an epoch: same on resume, disjoint across ranks."""
    order = np.random.default_rng([seed, STAGES.index(stage), epoch]).permutation(n)
    mine = order[rank * (n // world):(rank + 1) * (n // world)]
    return [mine[b:b + batch] for b in range(0, len(mine) - batch + 1, batch)] or [mine]


def train(cfg: TrainConfig, progress=True):
    """Run the stages of `cfg`; returns the trained model. Checkpoints go to cfg.out/last.pt.

    The paper's two: the shape classifier on single random views, then all of it on episodes; then
    (loc_epochs) FC_loc alone, learning FC_view's moves."""
    run = Trainer(cfg, progress)
    if run.wants("pretrain"):
        run.stage("pretrain", PretrainLoss(run.model, run.corrupt))
        run.save_pretrained()
    if run.wants("joint"):
        run.stage("joint", joint_loss(cfg, run.model, run.corrupt))
    if cfg.loc_epochs and run.wants("loc"):
        if (run.state["stage"], run.state["epoch"]) < (STAGES.index("joint"), cfg.joint_epochs):  # FC_view untrained
            done = run.state["epoch"] if run.state["stage"] == STAGES.index("joint") else 0
            raise InputError(f"stage loc: {cfg.out} has trained {done} of the {cfg.joint_epochs} joint epochs "
                             f"asked (--joint-epochs); resume it with --stage all first")
        run.stage("loc", LocLoss(run.model, cfg.steps, cfg.imitation_mix, run.corrupt, cfg.limits))
    return run.finish()


def joint_loss(cfg: TrainConfig, model, corrupt):
    """The episode loss of the joint stage for cfg.policy."""
    limits = cfg.limits
    if cfg.policy in ("reinforce", "hybrid"):
        rule = cfg.view_gradient if cfg.policy == "hybrid" else None
        return ReinforceLoss(model, cfg.steps, cfg.step_weighting, rule=rule,
                             reduction=cfg.gradient_reduction, corrupt=corrupt, limits=limits)
    if cfg.policy == "imitation":
        return ImitationLoss(model, cfg.steps, cfg.step_weighting, cfg.imitation_mix, corrupt, limits,
                             cfg.distill_loc, cfg.random_views, teacher_dtype(cfg.teacher_precision, cfg.device),
                             cfg.teacher_share)
    return JointLoss(model, cfg.steps, cfg.view_gradient, cfg.gradient_reduction,
                     cfg.step_weighting, cfg.revisit_penalty, corrupt, cfg.random_views, limits)


class Inputs(NamedTuple):
    """A batch's inputs that the network does not change (Trainer.inputs)."""

    rng: np.random.Generator
    torch_seed: int
    cameras: list
    views: list | None   # pre-training: (k, 2) views per camera
    depth: np.ndarray | tuple | None  # pre-training's images, or imitation's candidates (clean, seen)
    outliers: OutlierInputs | None = None  # the batch's unknown objects (cfg.outliers)
    limits: ViewLimits | None = None  # where the batch's episodes may look (Trainer.batch_limits)


class Trainer:
    """One training run: its data, model, optimiser state, metrics and checkpoints."""

    def __init__(self, cfg: TrainConfig, progress=True):
        self.cfg, self.progress = cfg, progress
        keep_freed_memory()  # each step's large blocks reused, not faulted in afresh
        self.rank, self.world = distributed(cfg.device)
        self.device = resolve_device(cfg.device, self.rank)
        torch.manual_seed(cfg.seed)
        self.out = output_dir(cfg.out, "out")
        self.ckpt_path, self.metrics_path = self.out / "last.pt", self.out / "metrics.csv"
        if cfg.resume and not self.ckpt_path.exists():
            raise InputError(f"resume: {self.ckpt_path} does not exist, so there is nothing to resume " + (
                "(stage loc fits FC_loc of a run trained before: give its --out)" if cfg.stage == "loc"
                else "(leave out --resume to start afresh)"))
        self.load_data()
        self.mcfg = replace(cfg.model, num_classes=len(self.classes))
        self.model = training_layout(RecurrentAttention(self.mcfg).to(self.device), self.device)
        camera = CameraConfig(self.mcfg.image_size, self.mcfg.image_size, radius=self.mcfg.radius)
        self.shapes, self.val = Shapes(self.train_ds, camera), Shapes(self.val_ds, camera)
        self.size_prior = size_prior.entry(self.shapes, len(self.classes))  # once: every checkpoint holds it
        self.augment = cfg.augment(camera)
        self.limits = cfg.limits
        self.starts = self.limits.initial_views(50)  # the paper's 50 initial views, in the band
        self.band = replace(self.limits, min_elevation=max(0.0, self.limits.min_elevation))  # band_share's
        self.band_starts = self.band.initial_views(50)
        self.corrupt = self.augment.images if self.augment.changes_images else None
        self.outliers = (Outliers(camera, self.augment, self.limits, cfg.outliers, cfg.outlier_batch,
                                  cfg.views_per_shape, cfg.near_outliers, cfg.real_outliers,
                                  cfg.real_outliers_root, cfg.outlier_margins) if cfg.outliers else None)
        if cfg.render_process and self.world > 1:
            raise InputError("render_process: one process trains with a render worker; under torchrun "
                             "each rank renders its own batches (leave out --render-process)")
        self.worker = None  # render_worker.RenderWorker, started by the first epoch that wants it
        self.state = {"stage": 0, "epoch": 0, "batch": 0, "step": 0}
        self.rows, elapsed, self.opt_state, self.saved = [], 0.0, None, None
        if cfg.resume:
            ckpt = checkpoint.read_fitting(self.ckpt_path, self.mcfg, self.classes, resumable=True,
                                           grow_loc=True)
            self.state, elapsed = dict(ckpt["state"]), ckpt["elapsed"]
            checkpoint.check_resume_settings(self.ckpt_path, ckpt.get("config"), cfg.to_dict())
            # a run without FC_loc's hidden layer takes one before stage loc, as a fresh run has it
            grown = ckpt["model_args"].get("loc_hidden", 0) != self.mcfg.loc_hidden
            if grown and self.state["stage"] >= STAGES.index("loc"):
                raise checkpoint.CheckpointError(self.ckpt_path, "its stage loc ran without FC_loc's hidden layer")
            self.model.load_state_dict(ckpt["model"], strict=not grown)
            self.opt_state = ckpt["optimizer"]
            self.rows, self.saved = read_metrics(self.metrics_path), self.state["step"]
            self.log(f"resumed from {self.ckpt_path} at {({k: self.state[k] for k in checkpoint.STATE})}")
        self.load_pretrained()
        self.start = time.perf_counter() - elapsed

    def load_data(self):
        cfg, cache = self.cfg, default_cache_dir()
        # per-epoch figures on the validation split; the test split stays unread until the end
        parts = open_splits(cfg.dataset, cfg.root, ("train", "val"), cache)
        self.train_ds, self.val_ds = parts["train"].require_objects(), parts["val"]
        self.classes = list(self.train_ds.classes)
        if len(self.classes) < 2:
            raise InputError(f"{self.train_ds.layout or cfg.dataset}: {len(self.classes)} class "
                             f"{self.classes}; recognising needs at least 2")
        if cfg.max_shapes:  # a seeded subset with every class in it
            self.train_ds.keep(subset_with_every_class(self.train_ds.labels(), cfg.max_shapes, cfg.seed))

    def load_pretrained(self):
        """A joint stage run on its own starts from the run's pretrained.pt."""
        if self.cfg.stage != "joint" or self.cfg.resume:
            return
        if (self.out / "pretrained.pt").exists():
            self.model.load_state_dict(checkpoint.read_fitting(
                self.out / "pretrained.pt", self.mcfg, self.classes)["model"])
        else:
            self.log(f"warning: no {self.out / 'pretrained.pt'}: the joint stage starts from an "
                     f"untrained classifier")

    def log(self, text):
        if self.rank == 0:
            print(text, file=sys.stderr)

    def wants(self, stage):
        """Whether `stage` is to run (asked for, and not finished before a resume)."""
        s = STAGES.index(stage)
        return self.cfg.stage in ("all", stage) and s >= self.state["stage"]

    def optimizer(self, stage):
        """Adam over the model, FC_loc at its own rate in the joint stage (its hidden layer,
        loc_hidden, waits for stage loc, which steps FC_loc alone); a resumed run's state."""
        cfg, named = self.cfg, list(self.model.named_parameters())
        if stage == "loc":
            groups = [{"params": [p for n, p in named if n.startswith("locate")], "lr": cfg.lr_loc}]
        else:
            lr = cfg.lr_pretrain if stage == "pretrain" else cfg.lr_joint
            scale = cfg.lr_view_scale if stage == "joint" else 1.0
            groups = [{"params": [p for n, p in named if not n.startswith("locate")], "lr": lr},
                      {"params": [p for n, p in named if n.startswith("locate.")], "lr": lr * scale}]
        opt = torch.optim.Adam(groups)
        if self.opt_state is not None:
            try:
                opt.load_state_dict(self.opt_state)
            except (ValueError, KeyError, TypeError, RuntimeError) as e:
                raise checkpoint.CheckpointError(self.ckpt_path, f"its optimizer state does not fit "
                                                                 f"this run ({str(e)[:200]})") from None
            self.opt_state = None
        return opt

    def stage(self, stage, wrapper):
        s, cfg = STAGES.index(stage), self.cfg
        if s > self.state["stage"]:
            self.state.update(stage=s, epoch=0, batch=0, losses=[], accs=[])
            self.opt_state = None
        epochs = getattr(cfg, f"{stage}_epochs")
        if self.state["epoch"] >= epochs:  # finished before a resume: nothing to build
            return
        if stage == "joint" and self.state["epoch"] == self.state["batch"] == 0 and cfg.initial_step is not None:
            set_initial_step(self.model, cfg.initial_step)
        opt = self.optimizer(stage)
        # a head left unused (FC_loc in pre-training and undistilled imitation): DDP must know, or it waits
        net = (nn.parallel.DistributedDataParallel(wrapper, find_unused_parameters=True)
               if self.world > 1 else wrapper)
        for epoch in range(self.state["epoch"], epochs):
            losses, accs = (self.loc_round if stage == "loc" else self.epoch)(stage, epoch, epochs, net, opt)
            self.state.update(epoch=epoch + 1, batch=0, losses=[], accs=[])
            scored = (epoch + 1) % cfg.eval_every == 0 or epoch + 1 == epochs
            self.log_epoch(stage, epoch, losses, accs, scored)
            self.save_state(opt)
        # free DDP's reducer now: left to reference cycles it outlives destroy_process_group, and gloo's
        # threads then abort the process at exit ("terminate called without an active exception", CI)
        del net, wrapper
        gc.collect()

    def epoch(self, stage, epoch, epochs, net, opt):
        cfg = self.cfg
        todo = batches(len(self.shapes), cfg.batch_size, cfg.seed, stage, epoch, self.rank, self.world)
        bar = tqdm(range(self.state["batch"], len(todo)), desc=f"{stage} {epoch + 1}/{epochs}",
                   disable=not self.progress or self.rank != 0, file=sys.stderr, leave=False)
        losses, accs = list(self.state.get("losses", [])), list(self.state.get("accs", []))  # kept by a resume
        if cfg.render_process:  # a process of its own makes each batch's renders ahead
            self.worker = self.worker or RenderWorker(cfg, Trainer, joint_loss)
            ahead = AheadProcess(self.worker, lambda b: (stage, epoch, b, todo[b]),
                                 lambda b, made: self.remade(stage, epoch, b, todo[b], made))
        else:
            ahead = Ahead(lambda b: self.inputs(stage, epoch, b, todo[b], net), cfg.prefetch)
        for b in bar:
            loss, acc = self.train_step(stage, epoch, epochs, b, todo, net, opt,
                                        ahead.get(b, b + 1 if b + 1 < len(todo) else None))
            losses.append(loss)
            accs.append(acc)
            bar.set_postfix(loss=f"{np.mean(losses[-20:]):.3f}", acc=f"{np.mean(accs[-20:]):.3f}")
            self.state.update(batch=b + 1, step=self.state["step"] + 1, losses=losses, accs=accs)
            if self.state["step"] % cfg.checkpoint_every == 0:
                self.save_state(opt)
        ahead.close()
        return losses, accs

    def train_step(self, stage, epoch, epochs, b, todo, net, opt, inputs=None):
        """Batch b of todo (batches of shape indices), its loss stepped by opt: (loss, accuracy).
        `inputs`: the batch's, made ahead (Trainer.inputs), or None to make them now."""
        inputs = inputs or self.inputs(stage, epoch, b, todo[b], net)
        torch.manual_seed(inputs.torch_seed)
        loss, acc = self.batch_loss(stage, net, todo[b], inputs)
        where = f"{stage} epoch {epoch + 1}, batch {b + 1} (step {self.state['step'] + 1})"
        checkpoint.stop_if_diverged(self.model, where, self.ckpt_path, self.saved, loss.item())
        opt.zero_grad()
        loss.backward()
        set_lr(opt, lr_factor(self.cfg.lr_schedule, epoch * len(todo) + b, epochs * len(todo)))
        opt.step()
        return loss.item(), acc.item()

    def draws(self, stage, epoch, b, idx):
        """Batch b's first draws: (its generator's key, the generator, torch's seed, the
        augmented cameras of shapes idx)."""
        key = [self.cfg.seed, STAGES.index(stage), epoch, b, self.rank]
        rng = np.random.default_rng(key)
        seed = int(rng.integers(2 ** 31))
        cams = self.shapes.cameras(idx, self.augment, rng)
        return key, rng, seed, cams

    def batch_limits(self, key, stage):
        """Where the episodes of the batch keyed `key` may look: in the joint stage, at band_share's
        chance, the band above the object's centre (elevation >= 0, the recognizer's default), else
        the run's limits. Its own generator: every other draw is the batch's without it."""
        share = self.cfg.band_share if stage == "joint" else 0.0
        return self.band if share and np.random.default_rng([*key, BAND_STREAM]).random() < share else self.limits

    def starts_within(self, limits):
        return self.band_starts if limits is self.band else self.starts

    def outlier_inputs(self, key, stage, limits):
        # the outliers' own generator: the known batch draws from rng as it does without them
        return None if self.outliers is None else self.outliers.inputs(key, stage, self.starts_within(limits))

    def remade(self, stage, epoch, b, idx, made):
        """Batch b's inputs from the part a render worker made (render_worker.py): its
        cameras drawn again here, from the same seed, and its outliers."""
        key, _, _, cams = self.draws(stage, epoch, b, idx)
        rng, seed, views, depth = made
        limits = self.batch_limits(key, stage)
        return Inputs(rng, seed, cams, views, depth, self.outlier_inputs(key, stage, limits), limits)

    def inputs(self, stage, epoch, b, idx, net) -> Inputs:
        """What batch b (shapes idx) sees that the network does not change: its generator, the
        seed of torch's, the augmented cameras, and pre-training's views and images or
        imitation's candidate renders (a thread or a process may make them ahead: nothing here
        draws from torch's generator), and the batch's outliers."""
        key, rng, seed, cams = self.draws(stage, epoch, b, idx)
        loss = getattr(net, "module", net)  # under DDP, the loss it wraps
        limits = self.batch_limits(key, stage)
        odd = self.outlier_inputs(key, stage, limits)
        if stage == "joint":
            return Inputs(rng, seed, cams, None, loss.candidate_depth(cams, rng)
                          if hasattr(loss, "candidate_depth") else None, odd, limits)
        views = [self.limits.random_views(rng, self.cfg.views_per_shape) for _ in cams]
        return Inputs(rng, seed, cams, views, depth_layer.render_batch(cams, views), odd, limits)

    def loc_round(self, stage, epoch, epochs, net, opt):
        """Stage loc's epoch, a DAgger round: episodes on this rank's training shapes, then
        loc_passes passes fitting FC_loc to FC_view's moves in them."""
        cfg, loss = self.cfg, net  # one process (LocLoss refuses more): nothing wraps it
        rng = np.random.default_rng([cfg.seed, STAGES.index(stage), epoch, self.rank])
        torch.manual_seed(int(rng.integers(2 ** 31)))
        parts = [loss.collect(self.shapes.cameras(idx, self.augment, rng),
                              self.starts[rng.integers(0, len(self.starts), len(idx))])
                 for idx in batches(len(self.shapes), cfg.batch_size, cfg.seed, stage, epoch, self.rank, self.world)]
        states, targets, agree = (torch.cat(x) for x in zip(*parts))
        set_lr(opt, lr_factor(cfg.lr_schedule, epoch, epochs))
        mse = loss.fit(states, targets, opt, cfg.loc_passes, rng)
        self.state.update(step=self.state["step"] + 1)
        return [mse], [agree.float().mean().item()]

    def batch_loss(self, stage, net, idx, inputs):
        """(loss, accuracy) of one batch: single images of random views (pretrain) or whole
        episodes from one of the 50 initial views (joint)."""
        y = torch.as_tensor(self.shapes.labels[idx], device=self.device)
        odd = {} if inputs.outliers is None else {"outliers": inputs.outliers}
        if stage == "joint":
            limits = inputs.limits or self.limits
            if limits is not self.limits:  # the losses keep to the run's limits unless told
                odd["limits"] = limits
            starts = self.starts_within(limits)
            starts = starts[inputs.rng.integers(0, len(starts), len(idx))]
            known = () if inputs.depth is None else inputs.depth  # imitation's (clean, seen)
            return net(inputs.cameras, starts, y, *known, **odd)
        k = self.cfg.views_per_shape
        depth = self.augment.images(torch.from_numpy(inputs.depth))
        views = torch.as_tensor(np.concatenate(inputs.views), dtype=torch.float32, device=self.device)
        return net(depth.to(self.device), y.repeat_interleave(k), views, **odd)

    def log_epoch(self, stage, epoch, losses, accs, scored=True):
        """A metrics.csv row for the epoch: its loss and training accuracy, and where `scored` the
        validation shapes' accuracy (evaluation mode, its own seeded draws: the run's random
        streams and batch-norm statistics are untouched, so skipping it changes nothing learned)."""
        if self.rank != 0:
            return
        row = {"stage": stage, "epoch": epoch + 1, "step": self.state["step"],
               "wall_s": round(time.perf_counter() - self.start, 2),
               "loss": round(float(np.mean(losses)) if losses else float("nan"), 4),
               "train_acc": round(float(np.mean(accs)) if accs else float("nan"), 4),
               **evaluate_accuracy(self.model, self.val, self.cfg.eval_shapes if scored else 0, seed=self.cfg.seed,
                                   planner=None if stage == "loc" else own_planner(self.model, self.cfg.policy),
                                   limits=self.limits)}
        self.rows.append(row)
        write_metrics(self.metrics_path, self.rows)
        print(" ".join(f"{k}={v}" for k, v in row.items()), file=sys.stderr)

    def payload(self, **extra):
        return {"model": self.model.state_dict(), "model_args": self.mcfg.to_dict(),
                "classes": list(self.classes), **self.size_prior, **extra}

    def save_state(self, opt):
        if self.rank == 0:
            checkpoint.stop_if_diverged(self.model, f"step {self.state['step']}", self.ckpt_path, self.saved)
            checkpoint.save(self.ckpt_path, self.payload(
                optimizer=opt.state_dict(), state=dict(self.state), config=self.cfg.to_dict(),
                elapsed=time.perf_counter() - self.start))
            self.saved = self.state["step"]

    def save_pretrained(self):
        if self.rank == 0:
            checkpoint.stop_if_diverged(self.model, "the end of pre-training", self.ckpt_path, self.saved)
            checkpoint.save(self.out / "pretrained.pt", self.payload())

    def finish(self):
        if self.worker is not None:
            self.worker.close()
            self.worker = None
        if self.rank == 0:
            checkpoint.stop_if_diverged(self.model, "the end", self.ckpt_path, self.saved)
            checkpoint.save(self.out / "final.pt", self.payload(
                config=self.cfg.to_dict(), elapsed=time.perf_counter() - self.start))
        return self.model
