# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""Training: both stages end to end on small runs, resume to the same weights, stage loc,
torchrun with two processes and the metrics each run writes."""
import os
import re
import signal
import subprocess
import sys
import time

import pytest
import torch

from active_recognition.argument_checks import InputError
from active_recognition.model import checkpoint
from active_recognition.model.checkpoint import CheckpointError
from active_recognition.model.network import ModelConfig, RecurrentAttention
from active_recognition.training.train import TrainConfig, train

TINY = dict(pretrain_epochs=1, joint_epochs=2, batch_size=6, max_shapes=30, steps=3,
            views_per_shape=2, eval_shapes=0, checkpoint_every=2, seed=3,
            model={"hidden_size": 16, "feature_size": 16})


@pytest.fixture(autouse=True)
def cache(dataset_cache, monkeypatch):
    monkeypatch.setenv("ACTIVE_RECOGNITION_CACHE", str(dataset_cache))


def weights(path):
    return checkpoint.read(path)["model"]


def cli_args(out, **extra):
    cfg = {**TINY, **extra}
    args = [sys.executable, "-m", "active_recognition.cli", "train", "--out", str(out)]
    for k in ("pretrain_epochs", "joint_epochs", "batch_size", "max_shapes", "steps", "seed",
              "checkpoint_every", "eval_shapes"):
        args += ["--" + k.replace("_", "-"), str(cfg[k])]
    return args + ["--lr-schedule", "cosine"]  # a resumed run goes on along the schedule too


def test_checkpoint_round_trip(tmp_path):
    torch.manual_seed(0)
    model = RecurrentAttention(ModelConfig(num_classes=3, hidden_size=8))
    checkpoint.save(tmp_path / "m.pt", {"model": model.state_dict(),
                                        "model_args": model.config.to_dict(),
                                        "classes": ["a", "b", "c"]})
    loaded, classes, _ = checkpoint.load_model(tmp_path / "m.pt")
    x = torch.rand(2, 64, 64) * 255
    torch.testing.assert_close(loaded.classify_image(x), model.classify_image(x))
    assert classes == ["a", "b", "c"]
    assert not list(tmp_path.glob(".*tmp"))  # no temp file left behind


class Evil:
    def __reduce__(self):
        return (os.system, ("touch /tmp/active_recognition_pwned",))


def test_hostile_and_mismatched_checkpoints_are_refused(tmp_path):
    torch.save({"format": checkpoint.FORMAT, "model": Evil()}, tmp_path / "evil.pt")
    with pytest.raises(CheckpointError, match="refused"):
        checkpoint.load_model(tmp_path / "evil.pt")
    assert not os.path.exists("/tmp/active_recognition_pwned")
    good = RecurrentAttention(ModelConfig(num_classes=3, hidden_size=8))
    base = {"model": good.state_dict(), "model_args": good.config.to_dict(), "classes": ["a", "b", "c"]}
    cases = {
        "wrong_classes": ({**base, "classes": ["a", "b"]}, "class names"),
        "other_model": ({**base, "model_args": {**base["model_args"], "hidden_size": 9}}, "do not fit"),
        "bad_args": ({**base, "model_args": {"encoder": "vgg"}}, "bad model_args"),
        "unknown_arg": ({**base, "model_args": {**base["model_args"], "depth": 3}},
                        "unknown option model_args.depth"),
        "nan_weights": ({**base, "model": {k: v * float("nan") if k == "classify.bias" else v
                                           for k, v in base["model"].items()}},
                        "weight classify.bias holds NaN or infinite values"),
    }
    for name, (payload, reason) in cases.items():
        checkpoint.save(tmp_path / f"{name}.pt", payload)
        with pytest.raises(CheckpointError, match=reason):
            checkpoint.load_model(tmp_path / f"{name}.pt")
    torch.save({"model": {}}, tmp_path / "foreign.pt")
    with pytest.raises(CheckpointError, match="not an active_recognition checkpoint"):
        checkpoint.load_model(tmp_path / "foreign.pt")
    (tmp_path / "junk.pt").write_bytes(b"garbage" * 10)
    with pytest.raises(CheckpointError, match="unreadable"):
        checkpoint.load_model(tmp_path / "junk.pt")


@pytest.mark.slow
def test_killed_run_resumes_to_the_same_weights(tmp_path):
    env = {**os.environ, "OMP_NUM_THREADS": "1"}
    straight, killed = tmp_path / "straight", tmp_path / "killed"
    # the run that never stops and the one killed go side by side (one thread each): the same
    # commands as one after the other, in the time of the longer
    logs = [open(tmp_path / f"{out.name}.log", "w") for out in (straight, killed)]
    runs = [subprocess.Popen(cli_args(out), env=env, stdout=subprocess.DEVNULL, stderr=log)
            for out, log in zip((straight, killed), logs)]
    try:
        deadline = time.time() + 240
        while time.time() < deadline:  # SIGKILL once the joint stage has written a checkpoint
            try:
                if checkpoint.read(killed / "last.pt")["state"]["stage"] == 1:
                    break
            except CheckpointError:
                pass
            time.sleep(0.05)
        runs[1].send_signal(signal.SIGKILL)
        runs[1].wait()
        state = checkpoint.read(killed / "last.pt")["state"]
        assert state["stage"] == 1 and not (killed / "final.pt").exists(), state
        subprocess.run(cli_args(killed) + ["--resume"], check=True, env=env, capture_output=True,
                       timeout=300)
        assert runs[0].wait(timeout=300) == 0, (tmp_path / "straight.log").read_text()[-3000:]
    finally:
        for run, log in zip(runs, logs):
            run.kill()
            run.wait()
            log.close()
    a, b = weights(straight / "final.pt"), weights(killed / "final.pt")
    for k in a:
        torch.testing.assert_close(a[k], b[k], rtol=1e-5, atol=1e-6)


TORCHRUN_SCRIPT = """
import os, sys, torch, torch.distributed as dist
from active_recognition.training.train import TrainConfig, train
for name, values in eval(sys.argv[1]).items():  # one run after the other, in one process group
    model = train(TrainConfig(**values), progress=False)
    flat = torch.cat([p.detach().flatten() for p in model.parameters()])
    gathered = [torch.zeros_like(flat) for _ in range(dist.get_world_size())]
    dist.all_gather(gathered, flat)
    if dist.get_rank() == 0:
        print("MAXDIFF", name, max((g - gathered[0]).abs().max().item() for g in gathered), flush=True)
dist.barrier()
dist.destroy_process_group()
os._exit(0)  # as the CLI does: skip an interpreter teardown that gloo/embree threads can abort
"""
TORCHRUN_RUNS = {"end_to_end": {},
                 "imitation": {"policy": "imitation", "model": {**TINY["model"], "candidates": 8}}}


@pytest.fixture(scope="module")
def torchrun(tmp_path_factory, dataset_cache):
    """Every run of TORCHRUN_RUNS trained by one launch of 2 processes: (stdout, stderr, return
    code, their out folders). Starting the launcher and its workers (torch, the dataset) costs
    more than training any of these tiny runs, so they share one start."""
    tmp = tmp_path_factory.mktemp("torchrun")
    script = tmp / "ddp.py"
    script.write_text(TORCHRUN_SCRIPT)
    outs = {name: tmp / name for name in TORCHRUN_RUNS}
    cfgs = {name: {**TINY, "out": str(outs[name]), "joint_epochs": 1, **values}
            for name, values in TORCHRUN_RUNS.items()}
    # a session of its own, so a hang kills the launcher and both workers, not the launcher alone
    proc = subprocess.Popen([sys.executable, "-m", "torch.distributed.run", "--nproc_per_node=2",
                             "--standalone", str(script), repr(cfgs)], stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True, start_new_session=True,
                            env={**os.environ, "OMP_NUM_THREADS": "1",
                                 "ACTIVE_RECOGNITION_CACHE": str(dataset_cache)})
    try:
        stdout, stderr = proc.communicate(timeout=240)
    except subprocess.TimeoutExpired:
        os.killpg(proc.pid, signal.SIGKILL)
        proc.communicate()
        raise
    return stdout, stderr, proc.returncode, outs


@pytest.mark.slow
@pytest.mark.parametrize("run", TORCHRUN_RUNS)
def test_two_process_torchrun_on_cpu_agrees(torchrun, run):
    """The end-to-end policy and imitation, whose joint stage leaves FC_loc without a gradient:
    DDP stopped there ('Expected to have finished reduction') before it was told of unused heads."""
    stdout, stderr, code, outs = torchrun
    errors = [line for line in stderr.splitlines() if "Error" in line or "error" in line]
    assert code == 0, "\n".join(errors[-15:]) or stderr[-3000:]
    diffs = dict(line.split()[1:] for line in stdout.splitlines() if line.startswith("MAXDIFF"))
    assert float(diffs[run]) == 0.0
    assert (outs[run] / "final.pt").exists()


def test_an_initial_step_outside_the_bound_is_refused_before_any_training(tmp_path):
    with pytest.raises(ValueError, match="max_step"):  # by the configuration itself
        TrainConfig(**{**TINY, "out": str(tmp_path / "run"), "initial_step": [0.0, 0.9]})
    assert not (tmp_path / "run").exists()


def tiny(tree, out, **extra):
    """A run on the two-class folder tree that takes a few seconds."""
    return TrainConfig(**{"dataset": "folder", "root": str(tree), "out": str(out),
                          "pretrain_epochs": 1, "joint_epochs": 1, "batch_size": 4, "steps": 2,
                          "views_per_shape": 2, "eval_shapes": 0, "checkpoint_every": 1, "seed": 1,
                          "model": {"hidden_size": 8, "feature_size": 8}, **extra})


def test_a_diverging_run_stops_by_name_and_keeps_its_last_good_checkpoint(tiny_tree, tmp_path):
    run = tmp_path / "run"
    with pytest.raises(InputError) as e:
        train(tiny(tiny_tree, run, lr_pretrain=1e6), progress=False)  # Adam steps of ~1e6
    # caught by the loss of the next batch, or by the weights before a checkpoint is written
    m = re.fullmatch(r"training stopped at (?:pretrain epoch 1, batch \d+ \()?step (\d+)\)?: "
                     r"(?:the loss became (?:nan|inf)|weight [\w.]+ became non-finite) \(is a "
                     r"learning rate too high\?\); the last good checkpoint is (.+) \(step (\d+)\)",
                     str(e.value))
    assert m, str(e.value)
    assert m[2] == str(run / "last.pt") and int(m[3]) < int(m[1])
    kept = checkpoint.read(run / "last.pt")
    assert kept["state"]["step"] == int(m[3]) and checkpoint.nonfinite(kept["model"]) is None
    assert not (run / "final.pt").exists() and not (run / "pretrained.pt").exists()


def test_resume_with_nothing_to_resume_says_so_before_any_work(tmp_path):
    with pytest.raises(InputError, match="last.pt does not exist, so there is nothing to resume"):
        train(TrainConfig(resume=True, out=str(tmp_path / "run")), progress=False)
    assert list((tmp_path / "run").iterdir()) == []


def test_resuming_a_run_of_other_options_or_without_state_is_refused(tiny_tree, tmp_path):
    run = tmp_path / "run"
    train(tiny(tiny_tree, run, joint_epochs=0), progress=False)
    other = tiny(tiny_tree, run, resume=True, model={"hidden_size": 16, "feature_size": 8})
    with pytest.raises(CheckpointError, match=r"written with other model options \(hidden_size "
                                              r"8, this run 16\): use the same options"):
        train(other, progress=False)
    final = checkpoint.read(run / "final.pt")
    (run / "final.pt").replace(run / "last.pt")  # a finished model has no training state
    with pytest.raises(CheckpointError, match="holds no training state to resume from"):
        train(tiny(tiny_tree, run, resume=True), progress=False)
    state = {"stage": 1, "epoch": 0, "batch": 0, "step": 5}
    for bad, reason in [({"state": {"stage": "x"}, "optimizer": {}, "elapsed": 1.0},
                         "holds no training state"),
                        ({"state": state, "optimizer": {"state": {}, "param_groups": []},
                          "elapsed": 1.0}, "its optimizer state does not fit this run")]:
        checkpoint.save(run / "last.pt", {**final, **bad})
        with pytest.raises(CheckpointError, match=reason):
            train(tiny(tiny_tree, run, resume=True), progress=False)


@pytest.mark.slow
def test_cosine_schedule_runs_each_stage_from_its_rate_down_to_the_floor(tmp_path, monkeypatch):
    """The rate of every optimizer step, read where Adam steps, against the cosine written out."""
    import math
    from active_recognition.training.lr_schedule import FLOOR
    seen = []
    adam_step = torch.optim.Adam.step

    def recording(self, *a, **k):
        seen.append([g["lr"] for g in self.param_groups])
        return adam_step(self, *a, **k)
    monkeypatch.setattr(torch.optim.Adam, "step", recording)
    cfg = {**TINY, "pretrain_epochs": 2, "joint_epochs": 1, "lr_view_scale": 0.5}
    train(TrainConfig(**cfg, lr_schedule="cosine", out=str(tmp_path / "cos")), progress=False)
    per_stage = 30 // 6  # batches per epoch: 30 shapes in batches of 6
    stages = [(seen[:2 * per_stage], 1e-3, 1.0), (seen[2 * per_stage:], 3e-4, 0.5)]
    assert len(seen) == 3 * per_stage
    for lrs, base, scale in stages:
        n = len(lrs)
        for i, (rest, head) in enumerate(lrs):
            want = base * (FLOOR + (1 - FLOOR) * (1 + math.cos(math.pi * i / (n - 1))) / 2)
            assert rest == pytest.approx(want) and head == pytest.approx(want * scale), (i, lrs)
    seen.clear()
    train(TrainConfig(**cfg, out=str(tmp_path / "constant")), progress=False)
    assert {tuple(x) for x in seen} == {(1e-3, 1e-3), (3e-4, 1.5e-4)}


@pytest.mark.slow
def test_stage_loc_added_to_a_finished_run_gives_the_run_that_had_it_from_the_start(tmp_path):
    imitation = {**TINY, "policy": "imitation", "joint_epochs": 1,
                 "model": {**TINY["model"], "candidates": 8, "view_input": True}}
    grown = {**imitation, "loc_epochs": 2, "loc_passes": 3,
             "model": {**imitation["model"], "loc_hidden": 6}}
    train(TrainConfig(**imitation, out=str(tmp_path / "a")), progress=False)
    before = weights(tmp_path / "a" / "final.pt")
    train(TrainConfig(**grown, out=str(tmp_path / "a"), resume=True), progress=False)
    train(TrainConfig(**grown, out=str(tmp_path / "b")), progress=False)
    resumed, fresh = weights(tmp_path / "a" / "final.pt"), weights(tmp_path / "b" / "final.pt")
    added = {f"locate_mlp.{i}.{w}" for i in (0, 2) for w in ("weight", "bias")} | {"loc_fitted"}
    assert set(resumed) == set(fresh) == set(before) | added
    for k in fresh:
        assert torch.equal(resumed[k], fresh[k]), k
        if k in before and not k.startswith("loc"):
            assert torch.equal(fresh[k], before[k]), k  # stage loc steps FC_loc alone
    assert not torch.equal(fresh["locate_mlp.2.weight"], torch.zeros_like(fresh["locate_mlp.2.weight"]))
    rows = [line.split(",")[0] for line in (tmp_path / "b" / "metrics.csv").read_text().splitlines()]
    assert rows.count("loc") == 2


@pytest.mark.parametrize("values, message", [
    ({"loc_epochs": 2, "policy": "imitation", "model": {"candidates": 8}}, "and model.loc_hidden"),
    ({"loc_epochs": 2, "model": {"candidates": 8, "loc_hidden": 4}}, "needs policy imitation"),
])
def test_stage_loc_without_fc_view_or_a_hidden_layer_is_refused(values, message):
    with pytest.raises(InputError, match=message):
        TrainConfig(**values)


def test_stage_loc_waits_for_a_finished_joint_stage(tmp_path):
    imitation = {**TINY, "policy": "imitation", "joint_epochs": 1, "model": {**TINY["model"], "candidates": 8}}
    train(TrainConfig(**imitation, stage="pretrain", out=str(tmp_path / "a")), progress=False)
    grown = {**imitation, "loc_epochs": 1, "model": {**imitation["model"], "loc_hidden": 4}}
    with pytest.raises(InputError, match=r"has trained 0 of the 1 joint epochs asked \(--joint-epochs\); resume it "
                                         r"with --stage all first$"):
        train(TrainConfig(**grown, stage="loc", resume=True, out=str(tmp_path / "a")), progress=False)
    assert checkpoint.read(tmp_path / "a" / "last.pt")["state"]["stage"] == 0  # nothing was written
    with pytest.raises(InputError, match="stage loc fits FC_loc of a run trained before"):
        train(TrainConfig(**grown, stage="loc", resume=True, out=str(tmp_path / "none")), progress=False)


def test_a_run_stopped_after_an_epochs_last_batch_resumes_to_its_whole_loss(tmp_path, monkeypatch):
    """Saved after the last batch of pre-training's first epoch, stopped before that epoch's row:
    the resumed run logs the epoch's loss over all its batches, as the run that never stopped did.
    Before, it logged NaN (no batch left to run); from mid-epoch, the loss of the rest alone."""
    from active_recognition.training import train as train_module
    from active_recognition.training.run_metrics import read_metrics
    cfg = {**TINY, "pretrain_epochs": 2, "joint_epochs": 0, "checkpoint_every": 1}
    train(TrainConfig(**cfg, out=str(tmp_path / "straight")), progress=False)
    real = train_module.Trainer.log_epoch

    def stop(self, *args):
        raise KeyboardInterrupt
    monkeypatch.setattr(train_module.Trainer, "log_epoch", stop)
    with pytest.raises(KeyboardInterrupt):
        train(TrainConfig(**cfg, out=str(tmp_path / "stopped")), progress=False)
    monkeypatch.setattr(train_module.Trainer, "log_epoch", real)
    assert checkpoint.read(tmp_path / "stopped" / "last.pt")["state"]["epoch"] == 0
    train(TrainConfig(**cfg, out=str(tmp_path / "stopped"), resume=True), progress=False)
    straight, resumed = (read_metrics(tmp_path / r / "metrics.csv") for r in ("straight", "stopped"))
    assert [(r["epoch"], r["loss"], r["train_acc"]) for r in resumed] == \
        [(r["epoch"], r["loss"], r["train_acc"]) for r in straight]


def test_a_resume_with_settings_that_fix_the_batches_changed_is_refused(tmp_path):
    out = str(tmp_path / "run")
    train(TrainConfig(**{**TINY, "joint_epochs": 0}, out=out), progress=False)
    with pytest.raises(CheckpointError, match=r"was trained with other settings \(seed 3, this run 4; "
                                              r"batch_size 6, this run 5\)"):
        train(TrainConfig(**{**TINY, "joint_epochs": 1, "seed": 4, "batch_size": 5}, out=out, resume=True),
              progress=False)
    train(TrainConfig(**{**TINY, "joint_epochs": 1, "eval_shapes": 0}, out=out, resume=True), progress=False)


@pytest.mark.parametrize("ahead", [{"prefetch": True}, {"render_process": True}])
def test_batches_made_ahead_train_the_same_weights_bit_for_bit(tmp_path, ahead):
    """--prefetch makes each batch's augmented cameras and renders on a thread ahead of the
    network (prefetch.py), --render-process on a process of its own (render_worker.py): every draw
    comes from the batch's own generator, so the run is the same."""
    cfg = {**TINY, "policy": "imitation", "joint_epochs": 1, "mirror": 0.5, "stretch": 0.2,
           "frame_error": 0.05, "floor_cut": 0.05, "dropout": 0.1,
           "model": {**TINY["model"], "candidates": 8, "view_input": True}}
    train(TrainConfig(**cfg, out=str(tmp_path / "a")), progress=False)
    train(TrainConfig(**cfg, **ahead, out=str(tmp_path / "b")), progress=False)
    a, b = weights(tmp_path / "a" / "final.pt"), weights(tmp_path / "b" / "final.pt")
    assert a.keys() == b.keys()
    assert all(torch.equal(a[k], b[k]) for k in a)


def test_a_render_worker_that_cannot_start_says_why(tmp_path):
    """render_worker.RenderWorker: the worker's own error reaches the trainer, in its words."""
    from active_recognition.training.render_worker import RenderWorker
    from active_recognition.training.train import Trainer, joint_loss
    cfg = TrainConfig(**TINY, dataset="modelnet", root=str(tmp_path / "nowhere"), out=str(tmp_path / "o"))
    with pytest.raises(RuntimeError, match="render worker failed:(.|\n)*nowhere"):
        RenderWorker(cfg, Trainer, joint_loss)


def test_validation_every_few_epochs_leaves_blanks_and_trains_the_same_weights(tmp_path):
    """eval_every N scores the validation shapes at every Nth epoch of a stage and at its last;
    the weights are those of the run scored every epoch, bit for bit (evaluation draws nothing
    from the run's random streams and leaves batch norm's statistics alone)."""
    from active_recognition.training.run_metrics import read_metrics

    cfg = {**TINY, "policy": "imitation", "pretrain_epochs": 3, "joint_epochs": 1, "eval_shapes": 4,
           "model": {**TINY["model"], "candidates": 8, "view_input": True, "encoder": "wide"}}
    for name, every in (("each", 1), ("sparse", 2)):
        train(TrainConfig(**cfg, eval_every=every, out=str(tmp_path / name)), progress=False)
    each, sparse = (read_metrics(tmp_path / r / "metrics.csv") for r in ("each", "sparse"))
    assert [(r["stage"], r["epoch"]) for r in sparse] == [(r["stage"], r["epoch"]) for r in each]
    scored = [(r["stage"], r["epoch"]) for r in sparse if r["acc_3"] != ""]
    assert scored == [("pretrain", "2"), ("pretrain", "3"), ("joint", "1")]
    assert all(r["acc_3"] != "" for r in each)
    for a, b in zip(each, sparse):  # the same losses, and the same figures where both scored
        assert a["loss"] == b["loss"] and (b["acc_3"] == "" or a["acc_3"] == b["acc_3"])
    a, b = weights(tmp_path / "each" / "final.pt"), weights(tmp_path / "sparse" / "final.pt")
    assert all(torch.equal(a[k], b[k]) for k in a)
