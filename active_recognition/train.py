# Copyright 2026 active_recognition maintainers
#
# Licensed under the Apache License, Version 2.0 (the "License");
# you may not use this file except in compliance with the License.
# You may obtain a copy of the License at
#
#     http://www.apache.org/licenses/LICENSE-2.0
#
# Unless required by applicable law or agreed to in writing, software
# distributed under the License is distributed on an "AS IS" BASIS,
# WITHOUT WARRANTIES OR CONDITIONS OF ANY KIND, either express or implied.
# See the License for the specific language governing permissions and
# limitations under the License.

"""Two-stage training: pre-train the shape classifier, then train everything end to end.

Stage "pretrain": depth images of training shapes from random views, cross-entropy.
Stage "joint": episodes of `steps` views from the 50 initial views, cross-entropy at every step,
backpropagation through time; FC_loc learns through the depth layer's view gradient (policy
"learned"), by REINFORCE ("reinforce") or both ("hybrid"); with policy "imitation" FC_view learns
to pick the candidate view the oracle picks (DAgger: a step follows the oracle or FC_view).
Runs in one process or under torchrun (DistributedDataParallel, gloo on CPU, nccl on GPU).
"""
from __future__ import annotations

import csv
import gc
import math
import os
import sys
import time
from dataclasses import asdict, dataclass
from pathlib import Path

import numpy as np
import torch
import torch.distributed as dist
from torch import nn
from tqdm import tqdm

from . import checkpoint, geometry
from .augment import Augment
from .datasets import NAMES, default_cache_dir, open_dataset
from .depth_layer import CameraConfig, DepthCamera, GRADIENT_RULES
from .episode import Episode, EpisodeConfig, run
from .model import ModelConfig, RecurrentAttention
from .policies import lookahead_logits, visited_mask
from .validation import Check, InputError, SEED_MAX, option, output_dir, validate

STAGES = ("pretrain", "joint")
STEP_WEIGHTINGS = ("uniform", "early")
POLICIES = ("learned", "reinforce", "hybrid", "imitation")
MAX_EPOCHS = 100_000


@dataclass
class TrainConfig:
    dataset: str = option("procedural", choices=NAMES)
    root: str | None = option(None, kind=str, optional=True, length=(1, None))
    out: str = option("runs/procedural", length=(1, None))
    stage: str = option("all", choices=STAGES + ("all",))
    # learned (end to end) | reinforce | hybrid (both) | imitation
    policy: str = option("learned", choices=POLICIES)
    imitation_mix: float = option(0.5, lo=0, hi=1)  # imitation: chance a step follows the oracle
    revisit_penalty: float = option(0.0, lo=0)      # learned: weight of VERAM's revisit penalty
    pretrain_epochs: int = option(6, lo=0, hi=MAX_EPOCHS)
    joint_epochs: int = option(6, lo=0, hi=MAX_EPOCHS)
    batch_size: int = option(32, lo=1, hi=100_000)
    views_per_shape: int = option(4, lo=1, hi=1000)  # pre-training images per shape per batch
    steps: int = option(10, lo=1, hi=100)            # views per training episode
    lr_pretrain: float = option(1e-3, lo=0, lo_open=True)  # Adam; the paper's SGD used 0.01
    lr_joint: float = option(3e-4, lo=0, lo_open=True)     # the paper: 0.001
    view_gradient: str = option("surface", choices=GRADIENT_RULES)
    lr_view_scale: float = option(1.0, lo=0)  # FC_loc's learning rate relative to the rest (joint)
    step_weighting: str = option("uniform", choices=STEP_WEIGHTINGS)  # the joint loss's weights
    # (dtheta, dphi) rad: FC_loc's bias when the joint stage starts
    initial_step: list | None = option(None, kind=list, optional=True, length=(2, 2),
                                       items=Check(float))
    gradient_reduction: str = option("mean", choices=("mean", "sum"))
    eval_shapes: int = option(200, lo=0)        # test shapes scored after each epoch (0: none)
    checkpoint_every: int = option(50, lo=1)    # batches
    seed: int = option(0, lo=0, hi=SEED_MAX)
    device: str = option("cpu", pattern=r"cpu|cuda(:[0-9]+)?", text="cpu, cuda or cuda:N")
    resume: bool = option(False)
    max_shapes: int = option(0, lo=0)           # use only the first N training shapes (0: all)
    yaw: bool = option(False)                   # augment: objects turned by a random yaw
    frame_error: float = option(0.0, lo=0, hi=0.5, hi_open=True)  # augment: frame off by up to this
    floor_cut: float = option(0.0, lo=0, hi=0.5, hi_open=True)    # augment: bottom cut by up to this
    dropout: float = option(0.0, lo=0, hi=0.5, hi_open=True)      # augment: pixels missing, up to this
    model: dict = option({}, schema=ModelConfig)  # ModelConfig overrides

    def __post_init__(self):
        validate(self)
        if "num_classes" in self.model:
            raise InputError("model.num_classes comes from the dataset's classes: leave it out")
        if self.policy == "imitation" and not self.model.get("candidates"):
            raise InputError("policy imitation needs a view-scoring head: set model.candidates "
                             "(--candidates 50)")
        if self.initial_step is not None:  # refuse it now, not after pre-training
            initial_step_bias(self.initial_step, self.model.get("max_step", ModelConfig.max_step))
        epochs = {"pretrain": self.pretrain_epochs, "joint": self.joint_epochs}
        if not any(epochs[s] for s in (STAGES if self.stage == "all" else (self.stage,))):
            raise InputError(f"nothing to train: stage {self.stage} with pretrain_epochs "
                             f"{self.pretrain_epochs} and joint_epochs {self.joint_epochs}")

    def augment(self) -> Augment:
        """The augmentation these options ask for."""
        return Augment(self.yaw, self.frame_error, self.floor_cut, self.dropout)


def step_weights(steps, weighting="uniform"):
    """Weights of the per-step losses, summing to 1: uniform (the paper) or early (1/t, t = 1..T),
    which favours recognising after few views."""
    w = torch.ones(steps) if weighting == "uniform" else 1.0 / torch.arange(1, steps + 1)
    return w / w.sum()


def steps_loss(out, labels, weights):
    """The episode's loss: per-step cross-entropies, weighted (weights from step_weights)."""
    return sum(w * nn.functional.cross_entropy(s.logits, labels) for w, s in zip(weights, out))


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


class Shapes:
    """A dataset split with one lazily built DepthCamera per shape, or with `augment` (and an
    rng) a fresh camera around an augmented copy of each shape."""

    def __init__(self, ds, camera: CameraConfig):
        self.ds, self.camera, self._cams = ds, camera, {}
        self.labels = ds.labels()

    def __len__(self):
        return len(self.ds)

    def cameras(self, idx, augment: Augment | None = None, rng=None):
        if augment is not None and augment.meshes:
            return [augment.camera(*self.ds.mesh(i), self.camera, rng) for i in idx]
        for i in idx:
            if i not in self._cams:
                self._cams[i] = DepthCamera(*self.ds.mesh(i), self.camera)
        return [self._cams[i] for i in idx]


class PretrainLoss(nn.Module):
    """The shape classifier on single images (wrapped whole by DDP: one forward per backward)."""

    def __init__(self, model):
        super().__init__()
        self.model = model

    def forward(self, depth, labels, views=None):
        logits = self.model.classify_image(depth, views)
        return nn.functional.cross_entropy(logits, labels), (logits.argmax(1) == labels).float().mean()


class JointLoss(nn.Module):
    """A whole batch of episodes, rendered through the differentiable depth layer."""

    def __init__(self, model, steps, rule, reduction, weighting="uniform", revisit=0.0,
                 corrupt=None):
        super().__init__()
        self.model, self.steps, self.rule, self.reduction = model, steps, rule, reduction
        self.weights = step_weights(steps, weighting).tolist()
        self.revisit, self.corrupt = revisit, corrupt

    def forward(self, cameras, views, labels):
        ep = Episode(self.model, EpisodeConfig(max_views=self.steps, entropy_threshold=0.0))
        out = run(ep, cameras, views, self.steps, self.rule, self.reduction, self.corrupt)
        loss = steps_loss(out, labels, self.weights)
        if self.revisit:
            loss = loss + self.revisit * revisit_penalty(torch.stack(ep.views[:self.steps], 1))
        return loss, (out[-1].logits.argmax(1) == labels).float().mean()


def revisit_penalty(views, within=math.radians(30)):
    """VERAM's penalty on looking again where one has looked: for every view (B, T, 2) and each
    earlier one, how far the cosine of the angle between them exceeds cos(`within`), averaged.
    Differentiable in the views, so it pushes FC_loc's increments apart."""
    pos = geometry.unit_position(views)                                         # (B, T, 3)
    cos = pos @ pos.transpose(1, 2)                                              # (B, T, T)
    earlier = torch.ones_like(cos[0]).tril(-1).bool()
    return torch.relu(cos[:, earlier] - math.cos(within)).sum(1).mean()


class ReinforceLoss(nn.Module):
    """MV-RNN-style baseline: a Gaussian view policy trained with REINFORCE and a baseline.

    No gradient crosses the depth layer; the reward is a correct final prediction plus the
    entropy decrease over the episode (in units of log C); the baseline is a running mean.
    With `rule` (the hybrid policy) the renders are differentiable too: FC_loc learns from the
    depth layer's view gradient (through the sampled increments) and from REINFORCE at once.
    """

    def __init__(self, model, steps, weighting="uniform", std=0.3, entropy_weight=0.5, momentum=0.9,
                 rule=None, reduction="mean", corrupt=None):
        super().__init__()
        self.model, self.steps, self.std, self.corrupt = model, steps, std, corrupt
        self.rule, self.reduction = rule, reduction
        self.weights = step_weights(steps, weighting).tolist()
        self.entropy_weight, self.momentum = entropy_weight, momentum
        self.register_buffer("baseline", torch.zeros(()))

    def forward(self, cameras, views, labels):
        ep = Episode(self.model, EpisodeConfig(max_views=self.steps, entropy_threshold=0.0),
                     exploration_std=self.std, explore_through=self.rule is not None)
        out = run(ep, cameras, views, self.steps, self.rule, self.reduction, self.corrupt)
        ce = steps_loss(out, labels, self.weights)
        correct = (out[-1].logits.argmax(1) == labels).float()
        gain = torch.stack(ep.info_gain).sum(0) / math.log(out[-1].logits.shape[1])
        reward = correct + self.entropy_weight * gain
        advantage = reward - self.baseline
        with torch.no_grad():
            self.baseline.mul_(self.momentum).add_((1 - self.momentum) * reward.mean())
        policy = -(advantage.detach() * torch.stack(ep.log_probs).sum(0)).mean()
        return ce + policy, correct.mean()


class ImitationLoss(nn.Module):
    """FC_view imitates the oracle, DAgger-style; the classifier learns on the states visited.

    At every step the oracle tries each candidate view of each object with the current model
    and picks the one after which the true class is most probable (privileged, training only).
    FC_view is trained to pick it (cross-entropy over the candidates not yet visited). The next
    view is the oracle's with probability `mix`, else FC_view's, so FC_view also learns from
    states its own choices lead to. Renders are plain: no gradient crosses the depth layer.
    """

    def __init__(self, model, steps, weighting="uniform", mix=0.5, corrupt=None):
        super().__init__()
        self.model, self.steps, self.mix, self.corrupt = model, steps, mix, corrupt or (lambda d: d)
        self.weights = step_weights(steps, weighting).tolist()
        self.candidates = geometry.fibonacci_views(model.config.candidates)

    def oracle_targets(self, cand_features, hidden, labels, visited):
        """(B,) index of the best unvisited candidate for each object, by true-class loss."""
        with torch.no_grad():
            logits = lookahead_logits(self.model, cand_features, hidden, self.candidates)
            loss = nn.functional.cross_entropy(logits.transpose(1, 2), labels[:, None].expand(
                -1, logits.shape[1]), reduction="none")                              # (B, K)
            loss[torch.as_tensor(visited, device=loss.device)] = float("inf")
            return loss.argmin(1)

    def forward(self, cameras, views, labels):
        model, k = self.model, len(self.candidates)
        with torch.no_grad():
            depth = np.stack([c.render(self.candidates) for c in cameras])          # (B, K, H, W)
            depth = self.corrupt(torch.from_numpy(depth))
            feats = model.features(depth.flatten(0, 1).to(labels.device))
        self.labels, self.feats, self.head_losses = labels, feats.reshape(len(cameras), k, -1), []
        ep = Episode(model, EpisodeConfig(max_views=self.steps, entropy_threshold=0.0),
                     planner=self)
        out = run(ep, cameras, views, self.steps, corrupt=self.corrupt)  # plain renders
        loss = steps_loss(out, labels, self.weights) + torch.stack(self.head_losses).mean()
        return loss, (out[-1].logits.argmax(1) == labels).float().mean()

    def next_view(self, episode, step):
        """The planner of the training episode: oracle target, FC_view loss, DAgger choice."""
        visited = visited_mask(episode, self.candidates)
        target = self.oracle_targets(self.feats, episode.hidden, self.labels, visited)
        scores = self.model.score_views(episode.hidden)
        masked = scores.masked_fill(torch.as_tensor(visited, device=scores.device), float("-inf"))
        self.head_losses.append(nn.functional.cross_entropy(masked, target))
        follow = torch.rand(len(target), device=target.device) < self.mix
        choice = torch.where(follow, target, masked.detach().argmax(1))
        return self.candidates[choice.cpu().numpy()]


def distributed(device="cpu"):
    """(rank, world) and the process group, when started by torchrun: nccl on GPU, gloo on CPU."""
    world = int(os.environ.get("WORLD_SIZE", "1"))
    rank = int(os.environ.get("RANK", "0"))
    if world > 1 and not dist.is_initialized():
        dist.init_process_group("nccl" if device.startswith("cuda") else "gloo")
    return rank, world


def resolve_device(device, rank):
    """cuda on a torchrun rank means that rank's own GPU (LOCAL_RANK)."""
    if device == "cuda" and int(os.environ.get("WORLD_SIZE", "1")) > 1:
        return f"cuda:{int(os.environ.get('LOCAL_RANK', rank))}"
    if device.startswith("cuda") and not torch.cuda.is_available():
        raise InputError(f"device {device!r} asked for, but torch sees no CUDA GPU")
    return device


def batches(n, batch, seed, stage, epoch, rank, world):
    """This rank's batches of shape indices for an epoch: same on resume, disjoint across ranks."""
    order = np.random.default_rng([seed, STAGES.index(stage), epoch]).permutation(n)
    per_rank = n // world
    mine = order[rank * per_rank:(rank + 1) * per_rank]
    return [mine[b:b + batch] for b in range(0, len(mine) - batch + 1, batch)] or [mine]


def evaluate_accuracy(model, shapes, n, steps=(1, 3, 10), seed=0, planner=None):
    """Accuracy after 1, 3, 10 views from fixed initial views on a seeded sample of n shapes,
    with the model's own view head (or `planner`)."""
    if n <= 0 or not len(shapes):
        return {}
    rng = np.random.default_rng(seed)
    idx = np.sort(rng.permutation(len(shapes))[:n])  # a fixed, seeded subset of every class
    views = geometry.fibonacci_views(50)[rng.integers(0, 50, len(idx))]
    was = model.training
    model.eval()
    with torch.no_grad():
        out = run(Episode(model, EpisodeConfig(max_views=max(steps)), planner), shapes.cameras(idx),
                  views)
    model.train(was)
    y = torch.as_tensor(shapes.labels[idx], device=out[0].probs.device)
    return {f"acc_{k}": round((out[k - 1].probs.argmax(1) == y).float().mean().item(), 4) for k in steps}


def own_planner(model, policy):
    """The planner a run trains: FC_view for imitation, else the model's FC_loc (None)."""
    if policy == "imitation" and model.config.candidates:
        from .policies import ImitationPlanner
        return ImitationPlanner(model)
    return None


def write_metrics(path, rows):
    """Rewrite the metrics CSV atomically."""
    tmp = path.with_name(f".{path.name}.tmp")
    keys = list(dict.fromkeys(k for r in rows for k in r))
    with open(tmp, "w", newline="") as f:
        w = csv.DictWriter(f, keys)
        w.writeheader()
        w.writerows(rows)
    os.replace(tmp, path)


def read_metrics(path):
    if not Path(path).is_file():
        return []
    with open(path) as f:
        return list(csv.DictReader(f))


def stop_if_diverged(model, where, ckpt_path, saved, loss=None):
    """InputError when `loss` (if given), else any weight, is not finite: training has diverged.
    The message says where and which checkpoint is the last good one (none is overwritten)."""
    if loss is not None:
        bad = None if math.isfinite(loss) else f"the loss became {loss}"
    else:
        name = checkpoint.nonfinite(model.state_dict())
        bad = None if name is None else f"weight {name} became non-finite"
    if bad is None:
        return
    last = (f"the last good checkpoint is {ckpt_path} (step {saved})" if saved is not None else
            "no checkpoint had been written yet")
    raise InputError(f"training stopped at {where}: {bad} (is a learning rate too high?); {last}")


def train(cfg: TrainConfig, progress=True):
    """Run the stages of `cfg`; returns the trained model. Checkpoints go to cfg.out/last.pt."""
    rank, world = distributed(cfg.device)
    device = resolve_device(cfg.device, rank)
    torch.manual_seed(cfg.seed)
    out = output_dir(cfg.out, "out")
    ckpt_path, metrics_path = out / "last.pt", out / "metrics.csv"
    if cfg.resume and not ckpt_path.exists():
        raise InputError(f"resume: {ckpt_path} does not exist, so there is nothing to resume "
                         f"(leave out --resume to start afresh)")
    cache = default_cache_dir()
    train_ds = open_dataset(cfg.dataset, cfg.root, "train", cache_dir=cache).require_objects()
    if len(train_ds.classes) < 2:
        raise InputError(f"{train_ds.layout or cfg.dataset}: {len(train_ds.classes)} class "
                         f"{train_ds.classes}; recognising needs at least 2")
    test_ds = open_dataset(cfg.dataset, cfg.root, "test", cache_dir=cache)
    if cfg.max_shapes:  # a seeded subset with every class in it
        train_ds.keep(np.sort(np.random.default_rng(cfg.seed).permutation(len(train_ds))[:cfg.max_shapes]))
    mcfg = ModelConfig(**{"num_classes": len(train_ds.classes), **cfg.model})
    model = RecurrentAttention(mcfg).to(device)
    camera = CameraConfig(mcfg.image_size, mcfg.image_size, radius=mcfg.radius)
    shapes, test = Shapes(train_ds, camera), Shapes(test_ds, camera)
    augment = cfg.augment()
    corrupt = augment.images if augment.dropout > 0 else None
    state = {"stage": 0, "epoch": 0, "batch": 0, "step": 0}
    rows, elapsed, opt_state, saved = [], 0.0, None, None
    if cfg.resume:
        ckpt = checkpoint.read_fitting(ckpt_path, mcfg, train_ds.classes, resumable=True)
        model.load_state_dict(ckpt["model"])
        state, elapsed, opt_state = dict(ckpt["state"]), ckpt["elapsed"], ckpt["optimizer"]
        rows, saved = read_metrics(metrics_path), state["step"]
        if rank == 0:
            print(f"resumed from {ckpt_path} at {state}", file=sys.stderr)
    stages = STAGES if cfg.stage == "all" else (cfg.stage,)
    if cfg.stage == "joint" and not cfg.resume and (out / "pretrained.pt").exists():
        model.load_state_dict(checkpoint.read_fitting(out / "pretrained.pt", mcfg,
                                                      train_ds.classes)["model"])
    elif cfg.stage == "joint" and not cfg.resume and rank == 0:
        print(f"warning: no {out / 'pretrained.pt'}: the joint stage starts from an untrained "
              f"classifier", file=sys.stderr)
    start = time.perf_counter() - elapsed

    def save_state(opt):
        nonlocal saved
        if rank == 0:
            stop_if_diverged(model, f"step {state['step']}", ckpt_path, saved)
            payload = {"model": model.state_dict(), "model_args": mcfg.to_dict(),
                       "classes": list(train_ds.classes), "optimizer": opt.state_dict(),
                       "state": dict(state), "config": asdict(cfg),
                       "elapsed": time.perf_counter() - start}
            checkpoint.save(ckpt_path, payload)
            saved = state["step"]

    for s, stage in enumerate(STAGES):
        if stage not in stages or s < state["stage"]:
            continue
        if s > state["stage"]:
            state.update(stage=s, epoch=0, batch=0)
            opt_state = None
        fresh = state["epoch"] == 0 and state["batch"] == 0
        if stage == "joint" and fresh and cfg.initial_step is not None:
            set_initial_step(model, cfg.initial_step)
        lr = cfg.lr_pretrain if stage == "pretrain" else cfg.lr_joint
        head = list(model.locate.parameters())
        rest = [p for n, p in model.named_parameters() if not n.startswith("locate.")]
        scale = cfg.lr_view_scale if stage == "joint" else 1.0
        opt = torch.optim.Adam([{"params": rest, "lr": lr}, {"params": head, "lr": lr * scale}])
        if opt_state is not None:
            try:
                opt.load_state_dict(opt_state)
            except (ValueError, KeyError, TypeError, RuntimeError) as e:
                raise checkpoint.CheckpointError(ckpt_path, f"its optimizer state does not fit this "
                                                            f"run ({str(e)[:200]})") from None
            opt_state = None
        if stage == "pretrain":
            wrapper = PretrainLoss(model)
        elif cfg.policy in ("reinforce", "hybrid"):
            rule = cfg.view_gradient if cfg.policy == "hybrid" else None
            wrapper = ReinforceLoss(model, cfg.steps, cfg.step_weighting, rule=rule,
                                    reduction=cfg.gradient_reduction, corrupt=corrupt)
        elif cfg.policy == "imitation":
            wrapper = ImitationLoss(model, cfg.steps, cfg.step_weighting, cfg.imitation_mix, corrupt)
        else:
            wrapper = JointLoss(model, cfg.steps, cfg.view_gradient, cfg.gradient_reduction,
                                cfg.step_weighting, cfg.revisit_penalty, corrupt)
        # pre-training leaves FC_loc unused; DDP must be told, or it waits for its gradients
        net = (nn.parallel.DistributedDataParallel(wrapper, find_unused_parameters=stage == "pretrain")
               if world > 1 else wrapper)
        epochs = cfg.pretrain_epochs if stage == "pretrain" else cfg.joint_epochs
        for epoch in range(state["epoch"], epochs):
            todo = batches(len(shapes), cfg.batch_size, cfg.seed, stage, epoch, rank, world)
            bar = tqdm(range(state["batch"], len(todo)), desc=f"{stage} {epoch + 1}/{epochs}",
                       disable=not progress or rank != 0, file=sys.stderr, leave=False)
            losses, accs = [], []
            for b in bar:
                idx = todo[b]
                rng = np.random.default_rng([cfg.seed, s, epoch, b, rank])
                torch.manual_seed(int(rng.integers(2 ** 31)))
                y = torch.as_tensor(shapes.labels[idx], device=device)
                cams = shapes.cameras(idx, augment, rng)
                if stage == "pretrain":
                    k = cfg.views_per_shape
                    views = [geometry.random_views(rng, k) for _ in cams]
                    depth = augment.images(torch.from_numpy(np.concatenate(
                        [c.render(v) for c, v in zip(cams, views)])))
                    views = torch.as_tensor(np.concatenate(views), dtype=torch.float32, device=device)
                    loss, acc = net(depth.to(device), y.repeat_interleave(k), views)
                else:
                    views = geometry.fibonacci_views(50)[rng.integers(0, 50, len(idx))]
                    loss, acc = net(cams, views, y)
                stop_if_diverged(model, f"{stage} epoch {epoch + 1}, batch {b + 1} (step "
                                 f"{state['step'] + 1})", ckpt_path, saved, loss.item())
                opt.zero_grad()
                loss.backward()
                opt.step()
                losses.append(loss.item())
                accs.append(acc.item())
                bar.set_postfix(loss=f"{np.mean(losses[-20:]):.3f}", acc=f"{np.mean(accs[-20:]):.3f}")
                state.update(batch=b + 1, step=state["step"] + 1)
                if state["step"] % cfg.checkpoint_every == 0:
                    save_state(opt)
            state.update(epoch=epoch + 1, batch=0)
            if rank == 0:
                row = {"stage": stage, "epoch": epoch + 1, "step": state["step"],
                       "wall_s": round(time.perf_counter() - start, 2),
                       "loss": round(float(np.mean(losses)) if losses else float("nan"), 4),
                       "train_acc": round(float(np.mean(accs)) if accs else float("nan"), 4),
                       **evaluate_accuracy(model, test, cfg.eval_shapes, seed=cfg.seed,
                                           planner=own_planner(model, cfg.policy))}
                rows.append(row)
                write_metrics(metrics_path, rows)
                print(" ".join(f"{k}={v}" for k, v in row.items()), file=sys.stderr)
            save_state(opt)
        # free DDP's reducer now: left to reference cycles it outlives destroy_process_group, and
        # gloo's threads then abort the process at exit ("terminate called without an active
        # exception", seen in CI)
        del net, wrapper
        gc.collect()
        if stage == "pretrain" and rank == 0:
            stop_if_diverged(model, "the end of pre-training", ckpt_path, saved)
            checkpoint.save(out / "pretrained.pt", {"model": model.state_dict(),
                                                    "model_args": mcfg.to_dict(),
                                                    "classes": list(train_ds.classes)})
    if rank == 0:
        stop_if_diverged(model, "the end", ckpt_path, saved)
        checkpoint.save(out / "final.pt", {"model": model.state_dict(), "model_args": mcfg.to_dict(),
                                           "classes": list(train_ds.classes), "config": asdict(cfg),
                                           "elapsed": time.perf_counter() - start})
    return model
