# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""teacher_share: imitation's teacher ranks a random share of the candidates within reach, drawn
per batch; FC_view learns the best of those, for that share of the teacher's encoder work."""
import pytest
import torch

from active_recognition.argument_checks import InputError
from active_recognition.datasets.twins import make_shape
from active_recognition.model.network import ModelConfig, RecurrentAttention
from active_recognition.model.policies import teacher_choice
from active_recognition.sensing.depth_layer import DepthCamera
from active_recognition.sensing.reach import ViewLimits
from active_recognition.training.losses import ImitationLoss
from active_recognition.training.train import TrainConfig

TOP = ViewLimits(0.0, 90.0)
LABELS = torch.tensor([0, 1, 2])


def setup(share, steps=3):
    torch.manual_seed(2)
    model = RecurrentAttention(ModelConfig(num_classes=3, hidden_size=12, feature_size=8, candidates=20)).eval()
    cams = [DepthCamera(*make_shape(k, 3, False)) for k in range(3)]
    loss = ImitationLoss(model, steps=steps, mix=1.0, teacher_share=share)
    clean, seen = loss.candidate_depth(cams)
    return model, cams, loss, clean, seen


def spied(loss, model):
    """Run the loss's episode once; return what the teacher was given at each step and the
    number of images its encoder pass read."""
    targets, read, original, features = [], [], loss.oracle_targets, model.features
    loss.oracle_targets = lambda f, h, y, v: targets.append((f, h, v)) or original(f, h, y, v)
    model.features = lambda x: read.append(len(x)) or features(x)
    return targets, read


@pytest.mark.parametrize("limits", [None, TOP])
def test_the_teacher_ranks_a_share_of_the_candidates_in_reach_and_the_best_of_them(limits):
    model, cams, loss, clean, seen = setup(0.5)
    targets, read = spied(loss, model)
    torch.manual_seed(7)
    loss(cams, TOP.initial_views(50)[:3], LABELS, clean, seen, limits=limits)
    reach = torch.ones(20, dtype=torch.bool) if limits is None else torch.as_tensor(limits.allows(loss.candidates))
    ranked = ~loss.unranked
    assert ranked.sum() == max(4, round(0.5 * int(reach.sum())))  # never fewer than steps + 1
    assert read[0] == 3 * int(ranked.sum())  # the teacher's pass: 3 objects, the ranked candidates only
    assert not (ranked & ~reach).any()
    with torch.no_grad():
        every = model.features(seen.flatten(0, 1)).reshape(3, 20, -1)
    feats = targets[0][0]
    torch.testing.assert_close(feats[:, ranked], every[:, ranked])
    assert (feats[:, ~ranked] == 0).all()
    for f, hidden, excluded in targets:
        assert excluded[:, ~ranked.numpy()].all()  # never the teacher's choice
        best = teacher_choice(model, every, hidden, LABELS, loss.candidates, excluded)
        torch.testing.assert_close(teacher_choice(model, f, hidden, LABELS, loss.candidates, excluded), best)
        assert ranked[best].all()


def test_the_ranked_set_is_drawn_per_batch_from_torchs_generator():
    model, cams, loss, clean, seen = setup(0.5)
    drawn = []
    for seed in (7, 7, 8):
        torch.manual_seed(seed)
        loss(cams, TOP.initial_views(50)[:3], LABELS, clean, seen)
        drawn.append(loss.unranked.clone())
    assert torch.equal(drawn[0], drawn[1]) and not torch.equal(drawn[0], drawn[2])


def test_teacher_share_one_is_the_teacher_of_every_candidate():
    values = []
    for share in (1.0, 0.5):
        model, cams, loss, clean, seen = setup(share)
        torch.manual_seed(7)
        values.append(loss(cams, TOP.initial_views(50)[:3], LABELS, clean, seen)[0].item())
        if share == 1.0:
            assert loss.unranked is None
            model, cams, plain, clean, seen = setup(1.0)
            plain = ImitationLoss(model, steps=3, mix=1.0)
            torch.manual_seed(7)
            assert plain(cams, TOP.initial_views(50)[:3], LABELS, clean, seen)[0].item() == values[0]
    assert values[0] != values[1]


def test_teacher_share_is_checked():
    with pytest.raises(InputError, match=r"teacher_share must be"):
        TrainConfig(teacher_share=0.0)
    with pytest.raises(InputError, match=r"teacher_share must be"):
        TrainConfig(teacher_share=1.5)
    with pytest.raises(InputError, match=r"teacher_share: only imitation has a teacher, not policy reinforce"):
        TrainConfig(teacher_share=0.5, policy="reinforce")


def test_fc_views_loss_covers_only_the_ranked_candidates(monkeypatch):
    model, cams, loss, clean, seen = setup(0.5)
    logits, original = [], torch.nn.functional.cross_entropy
    monkeypatch.setattr(torch.nn.functional, "cross_entropy",
                        lambda x, y, *a, **k: logits.append((x.detach(), y)) or original(x, y, *a, **k))
    torch.manual_seed(7)
    loss(cams, TOP.initial_views(50)[:3], LABELS, clean, seen)
    heads = [(x, y) for x, y in logits if x.shape[1] == 20]  # FC_view's, over the candidates
    assert len(heads) == 3  # one a step
    for x, target in heads:
        assert torch.isinf(x[:, loss.unranked]).all()
        assert torch.isfinite(x.gather(1, target[:, None])).all()
