# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""band_share: a share of the joint stage's batches keeps its episodes above the object's centre
(the recognizer's default band), the rest look over the whole sphere; imitation's teacher then
reads only the candidates within reach, and chooses as it would reading them all."""
from types import SimpleNamespace

import numpy as np
import pytest
import torch

from active_recognition.argument_checks import InputError
from active_recognition.datasets.twins import make_shape
from active_recognition.model import episode as episode_module
from active_recognition.model.network import ModelConfig, RecurrentAttention
from active_recognition.model.policies import teacher_choice
from active_recognition.sensing.depth_layer import DepthCamera
from active_recognition.sensing.reach import ViewLimits
from active_recognition.training.losses import ImitationLoss
from active_recognition.training.train import TrainConfig, Trainer, train

TOP = ViewLimits(0.0, 90.0)
TINY = dict(pretrain_epochs=1, joint_epochs=1, batch_size=5, max_shapes=20, steps=3,
            views_per_shape=2, eval_shapes=0, seed=5, policy="imitation",
            model={"hidden_size": 12, "feature_size": 8, "candidates": 20})


def elevations(views):
    return 90 - np.degrees(np.asarray(views, dtype=np.float64).reshape(-1, 2)[:, 0])


def test_band_share_is_refused_where_every_view_is_in_the_band_already():
    with pytest.raises(InputError, match=r"band_share: min_elevation 0 keeps every view above the "
                                         r"object's centre already"):
        TrainConfig(band_share=0.5, limits={"min_elevation": 0.0})
    with pytest.raises(InputError, match=r"band_share must be"):
        TrainConfig(band_share=1.5)


def test_a_share_of_joint_batches_keeps_to_the_band_and_no_pretraining_batch_does():
    sphere = ViewLimits()

    def limits(share, stage, n=600):
        run = SimpleNamespace(cfg=SimpleNamespace(band_share=share), band=TOP, limits=sphere)
        return [Trainer.batch_limits(run, [0, 1, 0, b, 0], stage) for b in range(n)]

    drawn = limits(0.3, "joint")
    assert abs(np.mean([x is TOP for x in drawn]) - 0.3) < 0.06  # 4 standard errors
    assert all(x is sphere for x in limits(0.3, "pretrain") + limits(0.0, "joint"))
    assert [x is TOP for x in drawn] == [x is TOP for x in limits(0.3, "joint")]  # seeded


def small_model():
    torch.manual_seed(2)
    return RecurrentAttention(ModelConfig(num_classes=3, hidden_size=12, feature_size=8,
                                          candidates=20)).eval()  # batch norm: running statistics


def test_the_teacher_reads_the_candidates_in_reach_and_chooses_as_from_all_of_them():
    model = small_model()
    cams = [DepthCamera(*make_shape(k, 3, False)) for k in range(3)]
    labels = torch.tensor([0, 1, 2])
    loss = ImitationLoss(model, steps=3, mix=1.0)
    clean, seen = loss.candidate_depth(cams)
    inside = TOP.allows(loss.candidates)
    assert 0 < inside.sum() < len(inside)
    targets = []
    original = loss.oracle_targets
    loss.oracle_targets = lambda f, h, y, v: targets.append((f, h, v)) or original(f, h, y, v)
    loss(cams, TOP.initial_views(50)[:3], labels, clean, seen, limits=TOP)
    with torch.no_grad():
        every = model.features(seen.flatten(0, 1)).reshape(3, len(inside), -1)
    feats = targets[0][0]
    torch.testing.assert_close(feats[:, inside], every[:, inside])
    assert (feats[:, ~inside] == 0).all()
    for f, hidden, visited in targets:
        assert visited[:, ~inside].all()  # out of reach: never the teacher's choice
        torch.testing.assert_close(teacher_choice(model, every, hidden, labels, loss.candidates, visited),
                                   teacher_choice(model, f, hidden, labels, loss.candidates, visited))


@pytest.fixture
def episodes(monkeypatch, dataset_cache):
    """The views of every training episode run (each a list of (B, 2) views)."""
    monkeypatch.setenv("ACTIVE_RECOGNITION_CACHE", str(dataset_cache))
    seen, original = [], episode_module.run

    def spy(ep, *args, **kwargs):
        out = original(ep, *args, **kwargs)
        seen.append(torch.stack(ep.views[:len(out)]).detach().numpy())
        return out
    monkeypatch.setattr("active_recognition.training.losses.run", spy)
    return seen


@pytest.mark.parametrize("process", [False, True])
def test_band_share_one_keeps_every_joint_episode_above_the_centre(tmp_path, episodes, process):
    train(TrainConfig(**TINY, band_share=1.0, render_process=process, out=str(tmp_path / "band")),
          progress=False)
    assert len(episodes) == 4  # 20 shapes in batches of 5
    assert all((elevations(v) >= -1e-4).all() for v in episodes)
    episodes.clear()
    train(TrainConfig(**TINY, out=str(tmp_path / "sphere")), progress=False)
    assert min(elevations(v).min() for v in episodes) < -10  # the whole sphere, without it
