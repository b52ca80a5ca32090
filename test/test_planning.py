# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""Looking must pay: the twins benchmark, view-set scoring, the fixed and imitation planners, the
view input and the imitation targets, each against an independent computation."""
import itertools
import math

import numpy as np
import pytest
import torch

from active_recognition.datasets import open_dataset
from active_recognition.datasets.shapes import Shapes
from active_recognition.datasets.twins import CLASSES, PAIRS, make_shape
from active_recognition.evaluation.shared_classifier import MultiViewClassifier
from active_recognition.evaluation.view_sets import (
    best_fixed_views, best_subset_accuracy, candidate_features, extend_fixed_views, fixed_path,
    subset_logits,
)
from active_recognition.model.episode import Episode, EpisodeConfig, run
from active_recognition.model.network import ModelConfig, RecurrentAttention
from active_recognition.model.policies import FixedPlanner, ImitationPlanner, make_planner, nearest_candidates
from active_recognition.sensing import geometry
from active_recognition.sensing.depth_layer import CameraConfig, DepthCamera
from active_recognition.sensing.reach import ViewLimits
from active_recognition.training.losses import ImitationLoss


def face_view(axis, sign, tilt=0.0):
    """The view looking at face (axis, sign), tilted by `tilt` radians towards another axis."""
    normal = np.zeros(3)
    normal[axis] = sign
    other = np.zeros(3)
    other[(axis + 1) % 3] = 1.0
    _, theta, phi = geometry.view_from_position(math.cos(tilt) * normal + math.sin(tilt) * other)
    return theta, phi


@pytest.mark.parametrize("held_out", [False, True])
@pytest.mark.parametrize("pair", range(len(PAIRS)))
def test_twins_differ_only_where_their_niche_faces(pair, held_out):
    """Same seed, same proportions: the two classes of a pair render the same from every view
    more than 75 degrees from the telling face, and differently when looking into the niche."""
    _, axis, sign = PAIRS[pair]
    for seed in (3, 11):
        a, b = (DepthCamera(*make_shape(2 * pair + k, seed, held_out)) for k in (0, 1))
        far = np.array([v for v in geometry.fibonacci_views(60)
                        if geometry.camera_position(*v)[axis] * sign < math.cos(math.radians(75))])
        np.testing.assert_allclose(a.render(far), b.render(far), atol=0.01)  # of 255
        straight = np.array([face_view(axis, sign)])
        differ = (a.render(straight) != b.render(straight)).sum()
        assert differ >= 20, f"pair {pair}: only {differ} pixels tell the twins apart"


@pytest.mark.parametrize("pair", range(len(PAIRS)))
def test_every_twins_telling_face_is_seen_from_a_view_a_robot_can_take(pair):
    """The recognizer's default reach (no view from below the object's support): among the
    paper's 50 views inside it, some tell each pair's twins apart."""
    from active_recognition.sensing.reach import ViewLimits
    views = ViewLimits(0.0, 90.0).initial_views(50)
    assert len(views) and (np.array([geometry.camera_position(*v)[2] for v in views]) >= -1e-9).all()
    for seed in (3, 11):
        a, b = (DepthCamera(*make_shape(2 * pair + k, seed)) for k in (0, 1))
        differ = (a.render(views) != b.render(views)).sum((1, 2))
        assert differ.max() >= 20, f"pair {PAIRS[pair][0]}: no reachable view tells its twins apart"


def test_twins_cross_split_is_dressed_only_in_the_held_out_styles():
    from active_recognition.datasets.twins import dressing
    train = [dressing(np.random.default_rng(s)) for s in range(40)]
    held = [dressing(np.random.default_rng(s), held_out=True) for s in range(40)]
    assert {(d.edge, d.leg) for d in train} == {(e, k) for e in ("sharp", "bevel")
                                                for k in ("square", "round", "tapered")}
    assert {(d.edge, d.leg) for d in held} == {("round", "turned"), ("round", "splayed")}
    cross, test = (open_dataset("twins", split=s, per_class=1) for s in ("cross", "test"))
    assert not {p for p, _ in cross.items} & {p for p, _ in test.items}
    label, seed = cross.items[0][1], int(cross.items[0][0].split("/")[1])
    np.testing.assert_array_equal(cross.mesh(0)[0], make_shape(label, seed, held_out=True)[0])


def test_twins_dataset_is_generated_deterministically_with_every_class():
    ds = open_dataset("twins", split="test", per_class=2)
    again = open_dataset("twins", split="test", per_class=2)
    assert ds.classes == list(CLASSES) and len(CLASSES) == 12
    np.testing.assert_array_equal(ds.class_counts(), np.full(12, 2))
    for i in range(len(ds)):
        v, f = ds.mesh(i)
        np.testing.assert_array_equal(v, again.mesh(i)[0])
        assert np.abs(v).max() <= 0.5 + 1e-6 and np.isclose(np.ptp(v, 0).max(), 1.0, atol=1e-5)
    train = open_dataset("twins", split="train", per_class=2)
    assert not any(np.array_equal(train.mesh(i)[0], ds.mesh(i)[0]) for i in range(len(ds)))


@pytest.fixture(scope="module")
def toy():
    """A shared classifier with random weights and features of 5 objects at 7 candidates."""
    torch.manual_seed(0)
    net = MultiViewClassifier(4, feature_size=6)
    feats = torch.rand(5, 7, 6)
    labels = np.array([0, 1, 2, 3, 1])
    return net, feats, labels


def test_best_fixed_views_match_brute_force(toy):
    net, feats, labels = toy
    pair, acc = best_fixed_views(net, feats, labels, chunk=2)
    scores = {}
    with torch.no_grad():
        for p in itertools.combinations(range(7), 2):
            hits = [int(net.classify(feats[i, [f, *p]].amax(0)).argmax()) == labels[i]
                    for i in range(5) for f in range(7)]
            scores[p] = np.mean(hits)
    assert acc == pytest.approx(max(scores.values()))
    assert scores[tuple(pair)] == pytest.approx(max(scores.values()))


def test_extend_fixed_views_adds_the_best_view_one_at_a_time(toy):
    """Each added view is the one that, with every first view and the path so far, classifies
    the most (object, first view) pairs right: checked object by object, view by view."""
    net, feats, labels = toy
    path, accs = extend_fixed_views(net, feats, labels, [2, 5], 3)
    assert list(path[:2]) == [2, 5] and len(path) == 5 and len(set(path.tolist())) == 5
    with torch.no_grad():
        for k in range(2, 5):
            def score(c):
                return np.mean([int(net.classify(feats[i, [f, *path[:k], c]].amax(0)).argmax()) == labels[i]
                                for i in range(5) for f in range(7)])
            rest = [c for c in range(7) if c not in path[:k]]
            best = max(score(c) for c in rest)
            assert score(path[k]) == pytest.approx(best)
            assert accs[k - 2] == pytest.approx(best)
    assert len(extend_fixed_views(net, feats, labels, [2, 5], 0)[0]) == 2


def test_fixed_path_is_the_best_pair_then_its_extension_within_reach_each_view_once():
    torch.manual_seed(0)
    net = MultiViewClassifier(len(CLASSES), feature_size=8).eval()
    shapes = Shapes(open_dataset("twins", split="test", per_class=1), CameraConfig(64, 64))
    limits = ViewLimits(min_elevation=0.0)
    band = limits.initial_views(12)
    path, acc = fixed_path(net, shapes, candidates=12, limits=limits, length=40)
    assert len(path) == len(band) - 1  # no more views than the band has candidates, less the first
    index = nearest_candidates(path, band)
    assert np.allclose(band[index], path) and len(set(index.tolist())) == len(index)
    feats = candidate_features(net, shapes, np.arange(len(shapes)), band)
    pair, pair_acc = best_fixed_views(net, feats, shapes.labels)
    assert index[:2].tolist() == pair.tolist() and acc == pytest.approx(pair_acc)
    assert len(fixed_path(net, shapes, candidates=12, limits=limits)[0]) == 2  # the pair, by default
    assert len(fixed_path(net, shapes, candidates=12, limits=limits, length=0)[0]) == 1  # 1-view episodes


def test_best_subset_accuracy_matches_brute_force(toy):
    net, feats, labels = toy
    expected = []
    with torch.no_grad():
        for i, y in enumerate(labels):
            best = max(itertools.combinations(range(7), 3),
                       key=lambda s: net.classify(feats[i, list(s)].amax(0)).log_softmax(-1)[y])
            expected.append(int(net.classify(feats[i, list(best)].amax(0)).argmax()) == y)
    assert best_subset_accuracy(net, feats, labels, 3) == pytest.approx(np.mean(expected))
    logits = subset_logits(net, feats, np.array([[0, 1, 2]]))
    torch.testing.assert_close(logits[:, 0], net.classify(feats[:, :3].amax(1)))


def small_model(view_input=True, candidates=10, loc_hidden=0):
    torch.manual_seed(1)
    return RecurrentAttention(ModelConfig(num_classes=3, hidden_size=12, feature_size=8, view_input=view_input,
                                          candidates=candidates, loc_hidden=loc_hidden)).eval()


def test_view_input_makes_the_state_depend_on_where_the_image_was_taken():
    depth = torch.rand(2, 64, 64) * 255
    hidden = torch.zeros(2, 12)
    plain = small_model(view_input=False)
    a = plain(depth, hidden, torch.tensor([[0.3, 0.1], [1.0, 2.0]]))[2]
    b = plain(depth, hidden, torch.tensor([[2.0, -1.0], [0.1, 0.4]]))[2]
    torch.testing.assert_close(a, b)  # without the option the view is ignored
    model = small_model()
    a = model(depth, hidden, torch.tensor([[0.3, 0.1], [1.0, 2.0]]))[2]
    b = model(depth, hidden, torch.tensor([[2.0, -1.0], [0.1, 0.4]]))[2]
    assert not torch.allclose(a, b)
    with pytest.raises(ValueError, match="view_input"):
        model(depth, hidden)
    # the input is the camera's unit position, the same for equivalent (wrapped) views
    t, p = geometry.wrap_view(torch.tensor([4.0]), torch.tensor([0.5]))
    wrapped = model(depth[:1], hidden[:1], torch.stack([t, p], -1))[2]
    direct = model(depth[:1], hidden[:1], torch.tensor([[4.0, 0.5]]))[2]
    torch.testing.assert_close(wrapped, direct, atol=1e-5, rtol=1e-5)


def took_best_unvisited(model, ep, step, cands, seen):
    """Each object's next view is FC_view's best-scored candidate not in its `seen` set (by
    brute force over the scores), which then joins the set."""
    scores = model.score_views(ep.hidden)
    for b in range(len(seen)):
        order = [int(k) for k in torch.argsort(scores[b], descending=True)]
        best = next(k for k in order if k not in seen[b])
        np.testing.assert_allclose(step.next_view[b].numpy(), cands[best], atol=1e-6)
        seen[b].add(best)


def test_imitation_planner_takes_the_best_unvisited_candidate():
    model = small_model()
    planner = ImitationPlanner(model)
    ep = Episode(model, EpisodeConfig(max_views=10, entropy_threshold=0.0, travel_cost=0.0), planner)
    cands = geometry.fibonacci_views(10)
    ep.reset(torch.as_tensor(cands[[2, 5]], dtype=torch.float32))
    seen = [{2}, {5}]
    torch.manual_seed(3)
    with torch.no_grad():
        for _ in range(9):
            before = ep.hidden.clone()
            step = ep.step(torch.rand(2, 64, 64) * 255)
            took_best_unvisited(model, ep, step, cands, seen)
            assert not torch.equal(before, ep.hidden)
    assert all(len(s) == 10 for s in seen)  # ten views, ten different candidates: no revisit
    with pytest.raises(ValueError, match="view-scoring head"):
        make_planner("imitation", model=small_model(candidates=0))


def test_imitation_planner_pays_for_travel():
    """With travel_cost c each next view is the unvisited candidate with the best FC_view score
    less c x its great-circle angle from the view just taken (brute force, angles from dot
    products); a cost no score can pay takes the nearest unvisited candidate, and cost 0 is the
    plain planner."""
    model = small_model()
    cands = geometry.fibonacci_views(10)
    unit = geometry.camera_position(*cands.T)
    for cost in (0.0, 0.7, 100.0):
        ep = Episode(model, EpisodeConfig(max_views=10, entropy_threshold=0.0, travel_cost=cost),
                     ImitationPlanner(model))
        ep.reset(torch.as_tensor(cands[[2, 5]], dtype=torch.float32))
        seen, now = [{2}, {5}], [2, 5]
        torch.manual_seed(3)
        with torch.no_grad():
            for _ in range(9):
                step = ep.step(torch.rand(2, 64, 64) * 255)
                scores = model.score_views(ep.hidden).double().numpy()
                for b in range(2):
                    angle = np.arccos(np.clip(unit @ unit[now[b]], -1, 1))
                    value = [scores[b, k] - cost * angle[k] if k not in seen[b] else -np.inf for k in range(10)]
                    best = int(np.argmax(value))
                    if cost == 100:  # no score pays for that: the nearest unvisited
                        assert angle[best] == min(angle[k] for k in range(10) if k not in seen[b])
                    np.testing.assert_allclose(step.next_view[b].numpy(), cands[best], atol=1e-6)
                    seen[b].add(best)
                    now[b] = best
    np.testing.assert_allclose(geometry.angles_to(cands[:3], cands),
                               [[geometry.travel(cands[[i, k]]) for k in range(10)] for i in range(3)], atol=1e-9)


def test_fixed_planner_follows_its_path_then_looks_at_random():
    model = small_model(candidates=0)
    path = [[0.4, 1.0], [2.0, -2.0]]
    ep = Episode(model, EpisodeConfig(max_views=5, entropy_threshold=0.0), FixedPlanner(path, 0))
    ep.reset(torch.tensor([[1.0, 0.0], [2.5, 3.0]]))
    with torch.no_grad():
        views = [ep.step(torch.rand(2, 64, 64) * 255).next_view.numpy() for _ in range(4)]
    np.testing.assert_allclose(views[0], [path[0]] * 2, atol=1e-6)
    np.testing.assert_allclose(views[1], [path[1]] * 2, atol=1e-6)
    assert not np.allclose(views[2][0], views[2][1])  # then random, per object
    with pytest.raises(ValueError, match="path"):
        make_planner("fixed")


def test_fixed_then_imitation_follows_the_path_then_fc_views_best_unvisited_candidate():
    """fixed+imitation: the path's first two views (the pair), then FC_view's best-scored
    candidate among those not visited, the path's views (snapped to their candidates) counted
    as visited; the longer path's later views are the fixed planner's only."""
    model = small_model()
    cands = geometry.fibonacci_views(10)
    path = cands[[4, 7, 1, 8, 9]]
    planner = make_planner("fixed+imitation", model=model, fixed_path=path)
    ep = Episode(model, EpisodeConfig(max_views=8, entropy_threshold=0.0, travel_cost=0.0), planner)
    ep.reset(torch.as_tensor(cands[[2, 5]], dtype=torch.float32))
    seen = [{2}, {5}]
    torch.manual_seed(4)
    with torch.no_grad():
        for t in range(7):
            step = ep.step(torch.rand(2, 64, 64) * 255)
            if t < 2:
                np.testing.assert_allclose(step.next_view.numpy(), [path[t]] * 2, atol=1e-6)
                for b in range(2):
                    seen[b].add([4, 7][t])
                continue
            took_best_unvisited(model, ep, step, cands, seen)
    with pytest.raises(ValueError, match="fixed path"):
        make_planner("fixed+imitation", model=model)
    with pytest.raises(ValueError, match="needs its model"):
        make_planner("fixed+imitation", fixed_path=path)


def test_imitation_targets_are_the_candidates_after_which_the_true_class_is_likeliest():
    model = small_model(candidates=6)
    loss = ImitationLoss(model, steps=2)
    feats = torch.rand(2, 6, 8)
    hidden = torch.rand(2, 12)
    labels = torch.tensor([2, 0])
    visited = np.zeros((2, 6), dtype=bool)
    visited[0, 1] = visited[1, 4] = True
    target = loss.oracle_targets(feats, hidden, labels, visited)
    cands = torch.as_tensor(geometry.fibonacci_views(6), dtype=torch.float32)
    with torch.no_grad():
        for b in range(2):  # one candidate at a time, through the model's own step
            ce = []
            for k in range(6):
                x = model.cell_input(feats[b, k:k + 1], cands[k:k + 1])
                p = model.classify(model.cell(x, hidden[b:b + 1])).log_softmax(-1)[0]
                ce.append(math.inf if visited[b, k] else -float(p[labels[b]]))
            assert int(target[b]) == int(np.argmin(ce))


@pytest.mark.parametrize("readout", ["last", "mean", "mean+mirror"])
def test_the_oracle_takes_the_unvisited_candidate_after_which_the_answer_is_right_by_most(readout):
    """For each object, a copy of the episode steps through every candidate's own render: the
    oracle's next view is the unvisited one after which the episode's answer (its readout) puts
    the true class furthest above the strongest other."""
    model = small_model(candidates=8)
    model.config.readout = readout
    with torch.no_grad():  # sure answers that differ from view to view
        model.classify.weight.mul_(3)
    cams = [DepthCamera(*make_shape(c, seed)) for c, seed in ((0, 3), (1, 5), (4, 2))]
    labels = np.array([0, 2, 1])
    oracle = make_planner("oracle", cams, candidates=8, labels=labels)
    cands = geometry.fibonacci_views(8)
    ep = Episode(model, EpisodeConfig(max_views=3, entropy_threshold=0.0), oracle)
    with torch.no_grad():
        run(ep, cams, cands[[0, 3, 5]], steps=2)
    views = torch.stack(ep.views).numpy()                                      # (3, B, 2)
    for b, cam in enumerate(cams):
        seen = set(nearest_candidates(views[:2, b], cands))
        margins = []
        for k, view in enumerate(cands):
            trial = ep.fork(planner=None)  # the same state, its own records; FC_loc plans
            with torch.no_grad():
                p = trial.step(torch.from_numpy(np.stack([c.render(view[None])[0] for c in cams])),
                               torch.as_tensor(np.repeat(view[None], 3, 0))).probs[b]
            others = np.delete(p.numpy(), labels[b])
            margins.append(-math.inf if k in seen else float(p[labels[b]]) - others.max())
        np.testing.assert_allclose(views[2, b], cands[int(np.argmax(margins))])


def test_revisit_penalty_counts_close_pairs_and_pushes_views_apart():
    from active_recognition.training.losses import revisit_penalty
    far = torch.tensor([[[0.5, 0.0], [2.5, 3.0], [1.5, 1.5]]])
    assert float(revisit_penalty(far)) == 0.0  # every pair more than 30 degrees apart
    close = torch.tensor([[[1.0, 0.0], [1.0, 0.1], [2.5, 3.0]]], requires_grad=True)
    value = revisit_penalty(close)
    expected = math.cos(0.1 * math.sin(1.0)) - math.cos(math.radians(30))
    assert float(value.detach()) == pytest.approx(expected, abs=1e-4)
    value.backward()
    g = close.grad[0]
    assert g[1, 1] < 0 < g[0, 1]  # descent moves the two close views apart in phi
    assert torch.all(g[2] == 0)


def test_recognizer_planner_auto_is_the_checkpoint_default_and_oracle_is_refused(tmp_path):
    from active_recognition.model import checkpoint
    from active_recognition.runtime.active_recognizer import ActiveRecognizer, choose_planner
    model = small_model()
    payload = {"model": model.state_dict(), "model_args": model.config.to_dict(),
               "classes": ["a", "b", "c"]}
    checkpoint.save(tmp_path / "m.pt", payload)
    assert choose_planner("auto", model, payload) == "imitation"   # it has FC_view
    assert choose_planner("auto", small_model(candidates=0), payload) == "learned"
    checkpoint.save(tmp_path / "d.pt", {**payload, "default_planner": "straight"})
    assert ActiveRecognizer(tmp_path / "d.pt").planner == "straight"
    core = ActiveRecognizer(tmp_path / "m.pt", planner="random", seed=4)
    assert core.planner == "random"
    for privileged in ("oracle", "greedy"):
        with pytest.raises(ValueError, match="oracle needs the object's mesh, and so does greedy"):
            ActiveRecognizer(tmp_path / "m.pt", planner=privileged)
    with pytest.raises(ValueError, match="fixed planner needs its path"):
        ActiveRecognizer(tmp_path / "m.pt", planner="fixed")
    checkpoint.save(tmp_path / "f.pt", {**payload, "fixed_path": [[0.3, 0.2], [2.0, 1.0]]})
    core = ActiveRecognizer(tmp_path / "f.pt", planner="fixed")
    core.reset()
    obs = core.observe(np.full((64, 64), 0.8, dtype=np.float32))
    assert obs.next_view == pytest.approx((0.3, 0.2))


def test_hybrid_adds_the_depth_layer_gradient_to_reinforce():
    """With explore_through (the hybrid) the classification loss reaches FC_loc through the
    sampled increments and the depth layer; with plain REINFORCE it does not at all, and the
    sampled views are the same either way."""
    from active_recognition.training.losses import steps_loss
    ds = open_dataset("twins", split="test", per_class=1)
    cams = [DepthCamera(*ds.mesh(i)) for i in range(3)]
    views = geometry.fibonacci_views(50)[[3, 20, 41]]
    labels = torch.tensor([0, 1, 2])
    grads, paths = {}, {}
    for through in (False, True):
        model = small_model(candidates=0)
        ep = Episode(model, EpisodeConfig(3, 0.0), exploration_std=0.3, explore_through=through)
        torch.manual_seed(5)
        out = run(ep, cams, views, 3, "surface" if through else None)
        steps_loss(out, labels, [1 / 3] * 3).backward()
        grads[through] = model.locate.weight.grad
        paths[through] = torch.stack(ep.views, 1).detach()
    torch.testing.assert_close(paths[True], paths[False])
    assert grads[False] is None or float(grads[False].abs().sum()) == 0.0
    assert torch.isfinite(grads[True]).all() and float(grads[True].abs().sum()) > 0


def test_imitation_loss_trains_fc_view_and_not_fc_loc():
    ds = open_dataset("twins", split="test", per_class=1)
    cams = [DepthCamera(*ds.mesh(i)) for i in range(3)]
    cands = geometry.fibonacci_views(10)
    model = small_model(candidates=10).train()
    loss = ImitationLoss(model, steps=4, mix=1.0)  # always the oracle: views are its targets
    torch.manual_seed(0)
    value, acc = loss(cams, cands[[0, 4, 7]], torch.tensor([0, 1, 2]))
    value.backward()
    assert torch.isfinite(value) and 0 <= float(acc) <= 1
    assert float(model.score_views.weight.grad.abs().sum()) > 0   # FC_view learns
    assert model.locate.weight.grad is None                      # FC_loc is not used
    assert len(loss.head_losses) == 4


def test_evaluation_defaults_to_the_embedded_datasets_own_shipped_model():
    from active_recognition.evaluation.evaluate import EvalConfig, checkpoint_split
    for name in ("procedural", "twins"):
        model, classes, shapes, _ = checkpoint_split(None, EvalConfig(dataset=name))
        assert classes == list(shapes.ds.classes) and shapes.ds.name == name
    assert model.config.candidates == 50 and model.config.view_input  # twins.pt


def test_a_view_taken_far_from_its_request_marks_both_and_a_spent_sphere_ends_the_episode(tmp_path):
    from active_recognition.model import checkpoint
    from active_recognition.model.policies import exhausted, nearest_candidates, visited_mask
    from active_recognition.runtime.active_recognizer import ActiveRecognizer

    model = small_model(candidates=8)
    checkpoint.save(tmp_path / "m.pt", {"model": model.state_dict(),
                                        "model_args": model.config.to_dict(), "classes": ["a", "b", "c"]})
    core = ActiveRecognizer(tmp_path / "m.pt", EpisodeConfig(max_views=20, entropy_threshold=0.0),
                            planner="imitation")
    cands = core.planner_candidates
    assert len(cands) == 8
    core.reset(view=tuple(cands[0]))
    asked = np.array(core.view)
    far = cands[3] + np.array([0.05, 0.0])  # the arm went elsewhere: nearer another candidate
    depth = np.full((64, 64), 1.5, np.float32)
    seen = core.episode
    with torch.no_grad():
        seen.step(torch.rand(1, 64, 64) * 255, view=torch.tensor(far[None], dtype=torch.float32))
    marked = visited_mask(seen, cands)[0]
    both = {int(nearest_candidates(asked[None], cands)[0]), int(nearest_candidates(far[None], cands)[0])}
    assert len(both) == 2 and all(marked[i] for i in both)
    assert int(nearest_candidates(seen.view.numpy(), cands)[0]) not in both  # not asked again
    core.reset(view=tuple(cands[0]))
    steps = 0
    while not core.done:  # each step a new candidate; after the 8th, nothing is left
        obs = core.observe(depth)
        steps += 1
        assert steps <= 8
    assert steps == 8 and obs.status == "unsure" and exhausted(core.episode, cands)[0]


def test_distillation_teaches_fc_loc_the_increment_toward_the_oracles_view():
    from active_recognition.training.losses import increment_toward

    view = torch.tensor([[1.0, 3.0], [1.0, 0.2], [0.5, -0.1]])
    goal = torch.tensor([[1.3, -3.0], [2.5, 0.4], [0.4, 0.1]])
    # the short way round in phi (3.0 -> -3.0 is +0.28, not -6.0), each part clipped to 0.8
    np.testing.assert_allclose(increment_toward(view, goal, 0.8).numpy(),
                               [[0.3, 2 * math.pi - 6.0], [0.8, 0.2], [-0.1, 0.2]], atol=1e-6)
    torch.manual_seed(0)
    model = small_model(candidates=6)
    loss = ImitationLoss(model, steps=3, mix=1.0, distill=1.0)
    cams = [DepthCamera(*make_shape(k, 3, False)) for k in range(2)]
    opt = torch.optim.Adam(model.locate.parameters(), lr=0.05)
    errors = []
    for _ in range(30):  # FC_loc alone learns to point where the oracle looks
        value, _ = loss(cams, geometry.fibonacci_views(50)[:2], torch.tensor([0, 1]))
        opt.zero_grad()
        value.backward()
        opt.step()
        errors.append(float(loss.head_losses[1].detach()))
    assert np.mean(errors[-5:]) < 0.5 * np.mean(errors[:5])


def test_imitation_with_random_views_jumps_to_unvisited_candidates_at_its_rate():
    torch.manual_seed(1)
    model = small_model(candidates=12)
    cams = [DepthCamera(*make_shape(k % 12, 3, False)) for k in range(40)]
    labels = torch.tensor([k % 3 for k in range(40)])
    for rate in (0.0, 1.0):
        loss = ImitationLoss(model, steps=4, mix=1.0, random_views=rate)  # else: the teacher
        chosen, targets = [], []
        original = loss.oracle_targets

        def spy(*args):
            targets.append(original(*args))
            return targets[-1]
        loss.oracle_targets = spy
        step = loss.next_view
        loss.next_view = lambda ep, s: chosen.append(step(ep, s)) or chosen[-1]
        loss(cams, geometry.fibonacci_views(50)[:40], labels)
        picked = np.stack([nearest_candidates(c, loss.candidates) for c in chosen])   # (T, B)
        teacher = torch.stack(targets).numpy()
        assert all(len(set(col)) == len(col) for col in picked.T)  # never a visited one
        agree = (picked == teacher).mean()
        assert agree == 1.0 if rate == 0.0 else agree < 0.3


def test_stage_loc_targets_fc_views_moves_and_fitting_teaches_them_to_fc_loc_alone():
    from active_recognition.training.losses import LocLoss, increment_toward

    model = small_model(candidates=8, loc_hidden=16)
    cams = [DepthCamera(*make_shape(k, 3, False)) for k in range(4)]
    starts = geometry.fibonacci_views(50)[[3, 17, 30, 44]]
    loss = LocLoss(model, steps=4, mix=1.0)  # every step goes where FC_view points
    taken = []
    step = loss.next_view
    loss.next_view = lambda ep, s: taken.append(step(ep, s)) or taken[-1]
    states, targets, agree = loss.collect(cams, starts)
    assert states.shape == (16, model.config.state_size) and targets.shape == (16, 2) and agree.shape == (16,)
    # the views FC_view chose are the imitation planner's, run on its own (an independent rule)
    ep = Episode(model, EpisodeConfig(4, 0.0, 0.0), ImitationPlanner(model))
    with torch.no_grad():
        run(ep, cams, starts, 4)
    np.testing.assert_allclose(torch.stack(taken).numpy(), torch.stack(ep.views[1:]).numpy(), atol=1e-6)
    # each target is the bounded increment from the view of that step toward the next
    views = torch.stack(ep.views)                                                    # (T + 1, B, 2)
    want = torch.cat([increment_toward(views[t], views[t + 1], model.config.loc_bound) for t in range(4)])
    torch.testing.assert_close(targets, want)
    before = {k: v.clone() for k, v in model.state_dict().items()}
    opt = torch.optim.Adam([p for n, p in model.named_parameters() if n.startswith("locate")], 0.01)
    first = float(nn_mse(model.increment(states), targets))
    last = loss.fit(states, targets, opt, passes=200, rng=np.random.default_rng(0), batch=4)
    assert last < 0.2 * first
    changed = {k for k, v in model.state_dict().items() if not torch.equal(v, before[k])}
    assert changed and all(k.startswith("locate") for k in changed)  # the classifier is left as it was


def nn_mse(a, b):
    return ((a - b) ** 2).mean().detach()


def test_stage_loc_refuses_more_than_one_process(monkeypatch):
    from active_recognition.argument_checks import InputError
    from active_recognition.training.losses import LocLoss

    model = small_model(candidates=8, loc_hidden=4)
    monkeypatch.setattr(torch.distributed, "is_initialized", lambda: True)
    monkeypatch.setattr(torch.distributed, "get_world_size", lambda *a: 2)
    with pytest.raises(InputError, match="stage loc runs in one process"):
        LocLoss(model, steps=3)
    assert float(model.loc_fitted) == 0.0  # refused before it touched the model


def test_the_teacher_in_bfloat16_ranks_the_candidates_as_in_float32():
    """teacher_precision: the candidates' features in bfloat16 are float32's to bfloat16's
    precision, so the teacher's loss and choices barely move; float32 and bfloat16 are as asked,
    auto follows the hardware, anything else is refused by name."""
    from active_recognition.argument_checks import InputError
    from active_recognition.training.devices import teacher_dtype
    assert teacher_dtype("float32", "cpu") is None and teacher_dtype("bfloat16", "cpu") is torch.bfloat16
    assert teacher_dtype("auto", "cpu") in (None, torch.bfloat16)
    with pytest.raises(InputError, match="teacher_precision must be one of"):
        teacher_dtype("half", "cpu")
    torch.manual_seed(0)
    model = RecurrentAttention(ModelConfig(encoder="wide", num_classes=3, candidates=8)).train()
    cams = [DepthCamera(*make_shape(c, seed)) for c, seed in ((0, 3), (1, 5), (4, 2), (2, 7))]
    labels, views = torch.tensor([0, 2, 1, 1]), geometry.fibonacci_views(8)[:4]
    targets = {}
    for dtype in (None, torch.bfloat16):
        loss = ImitationLoss(model, steps=3, mix=1.0, teacher_dtype=dtype)
        clean, seen = loss.candidate_depth(cams)
        torch.manual_seed(1)
        value, _ = loss(cams, views, labels, clean, seen)
        targets[dtype] = loss.feats
        assert torch.isfinite(value) and loss.feats.dtype == torch.float32
    rel = (targets[None] - targets[torch.bfloat16]).norm() / targets[None].norm()
    assert 0 < rel < 0.03
