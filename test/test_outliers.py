# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""Outlier exposure (outliers.py): the loss against numpy, the known batches untouched by the
outliers' draws, and a tiny run whose outliers end less confidently classified than without."""
import math

import numpy as np
import pytest
import torch

from active_recognition.argument_checks import InputError
from active_recognition.sensing import depth_layer
from active_recognition.training import outliers
from active_recognition.training.losses import PretrainLoss
from active_recognition.training.train import TrainConfig, Trainer, train

TINY = dict(pretrain_epochs=2, joint_epochs=1, batch_size=6, max_shapes=24, steps=2, views_per_shape=2,
            eval_shapes=0, checkpoint_every=100, seed=5, policy="imitation", outlier_batch=4,
            model={"hidden_size": 16, "feature_size": 16, "candidates": 8, "view_input": True})


@pytest.fixture(autouse=True)
def few_unknowns(dataset_cache, monkeypatch):
    monkeypatch.setenv("ACTIVE_RECOGNITION_CACHE", str(dataset_cache))
    monkeypatch.setattr(outliers, "PER_CLASS", 3)  # 27 unknowns of the train styles


def test_uniform_ce_matches_numpy():
    logits = np.random.default_rng(0).normal(0, 3, (5, 7))
    logp = logits - logits.max(1, keepdims=True)
    logp -= np.log(np.exp(logp).sum(1, keepdims=True))
    expected = np.mean([-np.mean(row) for row in logp])
    assert outliers.uniform_ce(torch.tensor(logits)).item() == pytest.approx(expected, rel=1e-12)
    assert outliers.uniform_ce(torch.zeros(3, 7)).item() == pytest.approx(math.log(7))  # its least


def test_energy_margin_matches_numpy():
    rng = np.random.default_rng(1)
    known, unknown = rng.normal(0, 4, (6, 5)), rng.normal(0, 1, (4, 5))

    def free_energy(x):
        top = x.max(1)
        return -(top + np.log(np.exp(x - top[:, None]).sum(1)))

    for margins in ((-6.0, -2.0), (-3.0, 0.5), (-50.0, 50.0)):
        e_in, e_out = free_energy(known), free_energy(unknown)
        expected = (np.mean(np.maximum(e_in - margins[0], 0) ** 2)
                    + np.mean(np.maximum(margins[1] - e_out, 0) ** 2))
        got = outliers.energy_margin(torch.tensor(known), torch.tensor(unknown), margins).item()
        assert got == pytest.approx(expected, rel=1e-12)
    # within both bounds the loss is nothing: known energies -log(5) - 10, unknown ones -log(5)
    assert outliers.energy_margin(torch.full((2, 5), 10.0), torch.zeros(3, 5), (-9.0, -2.0)).item() == 0.0


def test_pretrain_energy_margins_weigh_both_groups_of_one_batch(tmp_path):
    run = Trainer(TrainConfig(**TINY, outliers=0.5, outlier_margins=[-4.0, -1.0], out=str(tmp_path / "m")),
                  progress=False)
    o = run.outliers.inputs([3], "pretrain", run.starts)
    assert o.margins == (-4.0, -1.0)
    rng = np.random.default_rng(2)
    views = rng.random((4, 2)) * [3.0, 6.0]
    depth = torch.from_numpy(depth_layer.render_batch(run.shapes.cameras(range(4)), [v[None] for v in views]))
    views, labels = torch.as_tensor(views, dtype=torch.float32), torch.arange(4) % len(run.classes)
    torch.manual_seed(0)
    total, _ = PretrainLoss(run.model)(depth, labels, views, o)
    odepth = torch.from_numpy(o.depth)
    both = run.model.classify_image(torch.cat([depth, odepth]),
                                    torch.cat([views, torch.as_tensor(o.views, dtype=torch.float32)]))
    energy = -torch.logsumexp(both.double(), -1).detach().numpy()
    ce = torch.nn.functional.cross_entropy(both[:4], labels).item()
    hinge = np.mean(np.maximum(energy[:4] + 4, 0) ** 2) + np.mean(np.maximum(-1 - energy[4:], 0) ** 2)
    assert total.item() == pytest.approx(ce + 0.5 * hinge, rel=1e-5)
    for bad, match in ((dict(outliers=0.5, outlier_margins=[-1.0, -4.0]), "must lie below"),
                       (dict(outlier_margins=[-4.0, -1.0]), "outliers above 0")):
        with pytest.raises(InputError, match=match):
            TrainConfig(**TINY, **bad, out=str(tmp_path / "x"))


def test_outliers_leave_the_known_batches_alone_and_add_their_own_term(tmp_path):
    off = Trainer(TrainConfig(**TINY, out=str(tmp_path / "off")), progress=False)
    on = Trainer(TrainConfig(**TINY, outliers=0.5, out=str(tmp_path / "on")), progress=False)
    assert off.outliers is None and on.outliers.shapes.ds.split == "train"
    for k, v in off.model.state_dict().items():
        assert torch.equal(v, on.model.state_dict()[k]), k
    idx = np.arange(6)
    a, b = off.inputs("pretrain", 0, 1, idx, None), on.inputs("pretrain", 0, 1, idx, None)
    assert a.outliers is None and b.outliers is not None and len(b.outliers.cameras) == 4
    assert a.torch_seed == b.torch_seed and np.array_equal(a.depth, b.depth)
    assert all(np.array_equal(x, y) for x, y in zip(a.views, b.views))
    assert a.rng.random() == b.rng.random()  # the known generator stands where it stood
    loss = PretrainLoss(on.model)
    plain, _ = on.batch_loss("pretrain", loss, idx, b._replace(outliers=None))
    total, _ = on.batch_loss("pretrain", loss, idx, b)
    o = b.outliers
    logits = on.model.classify_image(torch.from_numpy(o.depth), torch.as_tensor(o.views, dtype=torch.float32))
    logp = torch.log_softmax(logits.double(), -1).detach().numpy()
    assert (total - plain).item() == pytest.approx(0.5 * np.mean(-logp.mean(-1)), rel=1e-5)


def test_near_outliers_take_their_share_of_the_batch_and_keep_the_known_batch(tmp_path):
    from active_recognition.datasets.near import KINDS

    plain = Trainer(TrainConfig(**TINY, outliers=0.5, out=str(tmp_path / "plain")), progress=False)
    near = Trainer(TrainConfig(**TINY, outliers=0.5, near_outliers=0.5, out=str(tmp_path / "near")),
                   progress=False)
    assert near.outliers.near.ds.classes == list(KINDS) and len(near.outliers.near) == 3 * len(KINDS)
    idx = np.arange(6)
    a, b = plain.inputs("pretrain", 0, 1, idx, None), near.inputs("pretrain", 0, 1, idx, None)
    assert np.array_equal(a.depth, b.depth) and a.rng.random() == b.rng.random()
    assert len(b.outliers.cameras) == 4 and near.outliers.batch == near.outliers.near_batch == 2
    assert len(near.outliers.near._cams) == 2  # two furniture-like objects drawn for the batch
    assert b.outliers.depth.shape[0] == 4 * TINY["views_per_shape"]
    with pytest.raises(InputError, match="near_outliers"):
        TrainConfig(**TINY, outliers=0.5, near_outliers=1.5, out=str(tmp_path / "x"))


def test_real_outliers_take_their_share_from_the_train_split_alone(tmp_path):
    import trimesh

    root = tmp_path / "real"
    for split, kinds in (("train", ("crate", "shelf")), ("val", ("lamp",))):
        for i, kind in enumerate(kinds):
            (root / split / kind).mkdir(parents=True)
            for j in range(2):  # boxes of two proportions a kind, in metres
                box = trimesh.creation.box((0.3 + 0.2 * j, 0.4, 0.8 + 0.3 * i))
                (root / split / kind / f"repo__{kind}{j}.ply").write_bytes(box.export(file_type="ply"))
    plain = Trainer(TrainConfig(**TINY, outliers=0.5, out=str(tmp_path / "plain")), progress=False)
    real = Trainer(TrainConfig(**TINY, outliers=0.5, real_outliers=0.5, real_outliers_root=str(root),
                               out=str(tmp_path / "on")), progress=False)
    o = real.outliers
    assert o.real.ds.split == "train" and o.real.ds.classes == ["crate", "shelf"] and len(o.real) == 4
    assert o.batch == o.real_batch == 2 and o.near is None
    idx = np.arange(6)
    a, b = plain.inputs("pretrain", 0, 1, idx, None), real.inputs("pretrain", 0, 1, idx, None)
    assert np.array_equal(a.depth, b.depth) and a.rng.random() == b.rng.random()  # the known batch as it was
    assert len(b.outliers.cameras) == 4 and b.outliers.depth.shape[0] == 4 * TINY["views_per_shape"]
    assert len(o.real._cams) == 2  # two real meshes drawn for the batch
    for bad, match in ((dict(real_outliers=0.5), "real_outliers_root"),
                       (dict(real_outliers_root=str(root)), "real_outliers, which is 0"),
                       (dict(real_outliers=0.5, real_outliers_root=str(root), dataset="twins"), "no twins class"),
                       (dict(real_outliers=0.6, near_outliers=0.6, real_outliers_root=str(root)), "at most 1")):
        with pytest.raises(InputError, match=match):
            TrainConfig(**TINY, outliers=0.5, **bad, out=str(tmp_path / "x"))
    empty = tmp_path / "empty" / "train"
    empty.mkdir(parents=True)
    with pytest.raises(InputError, match="no mesh"):
        Trainer(TrainConfig(**TINY, outliers=0.5, real_outliers=0.5, real_outliers_root=str(empty.parent),
                            out=str(tmp_path / "e")), progress=False)


@pytest.mark.parametrize("margins", [None, [-1e3, 1e3]])
def test_a_joint_batch_adds_a_finite_outlier_episode_term(tmp_path, margins):
    from active_recognition.training.train import joint_loss

    cfg = TrainConfig(**TINY, outliers=1.0, outlier_margins=margins, out=str(tmp_path / "on"))
    run = Trainer(cfg, progress=False)
    loss = joint_loss(cfg, run.model, run.corrupt)
    inputs = run.inputs("joint", 0, 0, np.arange(6), loss)
    assert inputs.outliers.depth is None and len(inputs.outliers.cameras) == 4  # rendered as taken
    torch.manual_seed(0)
    plain, acc = run.batch_loss("joint", loss, np.arange(6), inputs._replace(outliers=None))
    torch.manual_seed(0)  # the same batch again: its inputs afresh, as batch_loss draws the starts from their rng
    total, same = run.batch_loss("joint", loss, np.arange(6), run.inputs("joint", 0, 0, np.arange(6), loss))
    term = (total - plain).item()
    if margins is None:
        assert math.isfinite(term) and term >= math.log(len(run.classes)) - 1e-5  # Jensen: CE to uniform >= log C
    else:  # both hinges about 1e3 squared: every free energy here lies within +-50 of 0
        assert 2 * 950 ** 2 < term < 2 * 1050 ** 2
    assert acc == same


def test_a_tiny_run_with_outliers_is_less_sure_of_them(tmp_path):
    sure = {**TINY, "pretrain_epochs": 6, "joint_epochs": 0, "lr_pretrain": 5e-3}  # confident on what it knows
    models = {w: train(TrainConfig(**sure, outliers=w, out=str(tmp_path / str(w))), progress=False)
              for w in (0.0, 2.0)}
    run = Trainer(TrainConfig(**TINY, outliers=1.0, out=str(tmp_path / "probe")), progress=False)
    o = run.outliers.inputs([99], "pretrain", run.starts)
    top = {}
    for w, model in models.items():
        with torch.no_grad():
            logits = model.eval().classify_image(torch.from_numpy(o.depth),
                                                 torch.as_tensor(o.views, dtype=torch.float32))
        top[w] = torch.softmax(logits, -1).max(-1).values.mean().item()
    assert top[2.0] < top[0.0] - 0.01, top  # seeded: 0.154 without, 0.125 with


def test_outliers_need_imitation_for_the_joint_stage(tmp_path):
    with pytest.raises(InputError, match="outliers"):
        TrainConfig(**{**TINY, "policy": "learned"}, outliers=1.0, out=str(tmp_path / "x"))


def test_the_outlier_episode_leaves_the_batch_norms_running_statistics_alone():
    """running_statistics_kept: inside it a training model's batch norms normalise by the batch's
    own statistics (as a training step does) and keep their running ones; after it they update
    again at their own momentum."""
    from active_recognition.model.network import ModelConfig, RecurrentAttention
    from active_recognition.training.outliers import running_statistics_kept
    torch.manual_seed(0)
    model = RecurrentAttention(ModelConfig(encoder="wide", num_classes=3)).train()
    norms = [m for m in model.modules() if isinstance(m, torch.nn.BatchNorm2d)]
    before = [m.running_mean.clone() for m in norms]
    depth = torch.rand(4, 64, 64) * 255
    with running_statistics_kept(model):
        inside = model.features(depth)
    assert all(torch.equal(a, m.running_mean) for a, m in zip(before, norms))
    torch.testing.assert_close(inside, model.features(depth))  # batch statistics, as outside
    assert not all(torch.equal(a, m.running_mean) for a, m in zip(before, norms))  # updating again


def test_pretraining_sees_the_outliers_in_one_batch_with_the_known_images():
    """PretrainLoss with outliers: one forward of known and outlier images together (a wide
    encoder's batch norms see both, as in Hendrycks et al.), cross-entropy on the known part and
    weight x uniform_ce on the rest, computed here again from the same batch."""
    from active_recognition.model.network import ModelConfig, RecurrentAttention
    from active_recognition.training.losses import PretrainLoss
    from active_recognition.training.outliers import OutlierInputs
    torch.manual_seed(0)
    model = RecurrentAttention(ModelConfig(encoder="wide", num_classes=3)).train()
    depth, labels = torch.rand(5, 64, 64) * 255, torch.tensor([0, 1, 2, 1, 0])
    views = torch.rand(5, 2)
    o = OutlierInputs(0.5, [], np.random.default_rng(1).random((3, 2)).astype(np.float32),
                      (np.random.default_rng(2).random((3, 64, 64)) * 255).astype(np.float32), None)
    loss, _ = PretrainLoss(model)(depth, labels, views, o)
    both = model.classify_image(torch.cat([depth, torch.from_numpy(o.depth)]),
                                torch.cat([views, torch.from_numpy(o.views)])).double()
    logp = torch.log_softmax(both, -1)
    expected = torch.nn.functional.nll_loss(logp[:5], labels) - 0.5 * logp[5:].mean()
    assert loss.item() == pytest.approx(expected.item(), rel=1e-5)


def test_a_tiny_run_with_energy_margins_sets_its_outliers_apart_by_free_energy(tmp_path):
    sure = {**TINY, "pretrain_epochs": 6, "joint_epochs": 0, "lr_pretrain": 5e-3}
    runs = {"off": {}, "energy": {"outliers": 1.0, "outlier_margins": [-4.0, -2.0]}}
    models = {k: train(TrainConfig(**sure, **kw, out=str(tmp_path / k)), progress=False) for k, kw in runs.items()}
    run = Trainer(TrainConfig(**TINY, outliers=1.0, out=str(tmp_path / "probe")), progress=False)
    o = run.outliers.inputs([99], "pretrain", run.starts)
    views = torch.as_tensor(o.views, dtype=torch.float32)
    odd = torch.from_numpy(o.depth)
    known = torch.from_numpy(depth_layer.render_batch(run.shapes.cameras(range(len(o.cameras))),
                                                      list(o.views.reshape(len(o.cameras), -1, 2))))
    gap = {}
    for k, model in models.items():
        with torch.no_grad():
            energy = [-torch.logsumexp(model.eval().classify_image(x, views), -1).mean().item() for x in (known, odd)]
        gap[k] = energy[1] - energy[0]
    assert gap["energy"] > gap["off"] + 0.1, gap  # seeded: 0.00 without, 0.70 with
