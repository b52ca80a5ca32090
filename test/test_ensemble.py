# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""ensemble.py and write_ensemble.py: several networks as one model, against each member run alone."""
import numpy as np
import pytest
import torch
import trimesh

from active_recognition.model import checkpoint
from active_recognition.model.ensemble import Ensemble
from active_recognition.model.episode import Episode, EpisodeConfig, lookahead_logits, run
from active_recognition.model.network import ModelConfig, RecurrentAttention, single_step
from active_recognition.model.policies import ImitationPlanner
from active_recognition.sensing.depth_layer import CameraConfig, DepthCamera
from active_recognition.training.write_ensemble import combine, main
from active_recognition.unknown import scores as open_set

OPTIONS = dict(num_classes=3, hidden_size=16, feature_size=16, candidates=5, view_input=True, memory="rnn+max",
               loc_hidden=8)


def member(tmp_path, name, seed, classes=("a", "b", "c"), **options):
    torch.manual_seed(seed)
    model = RecurrentAttention(ModelConfig(**{**OPTIONS, **options}))
    path = tmp_path / f"{name}.pt"
    checkpoint.save(path, {"model": model.state_dict(), "model_args": model.config.to_dict(),
                           "classes": list(classes), "default_planner": "imitation", "elapsed": 60.0 * seed,
                           "config": {"seed": seed}})
    return model.eval(), path


@pytest.fixture
def pair(tmp_path):
    (a, pa), (b, pb) = member(tmp_path, "a", 1), member(tmp_path, "b", 2)
    combine([pa, pb], tmp_path / "both.pt")
    return a, b, checkpoint.load_model(tmp_path / "both.pt")


def test_a_step_is_the_members_logits_averaged_and_their_states_side_by_side(pair):
    a, b, (ens, classes, ckpt) = pair
    assert isinstance(ens, Ensemble) and classes == ["a", "b", "c"] and ckpt["default_planner"] == "imitation"
    assert ckpt["elapsed"] == 180.0 and ckpt["config"] == {"seed": 1}  # both members' training, the first's options
    torch.manual_seed(0)
    depth, view = torch.rand(4, 64, 64) * 255, torch.rand(1, 2).expand(4, 2)  # one view: the look-ahead's
    with torch.no_grad():
        ha, hb = torch.rand(4, a.config.state_size), torch.rand(4, b.config.state_size)
        la, da, na = a(depth, ha, view)
        lb, db, nb = b(depth, hb, view)
        logits, delta, state = ens(depth, torch.cat([ha, hb], -1), view)
        assert ens.config.state_size == 2 * a.config.state_size == state.shape[1]
        assert torch.allclose(logits, (la + lb) / 2, atol=1e-6)
        assert torch.allclose(delta, da) and not torch.allclose(delta, db)
        assert torch.equal(state, torch.cat([na, nb], -1))
        views = (a.score_views(na).log_softmax(-1) + b.score_views(nb).log_softmax(-1)) / 2
        assert torch.allclose(ens.score_views(state), views, atol=1e-6)
        # the privileged planners' look-ahead: features, advance and classify compose to forward
        ahead = lookahead_logits(ens, ens.features(depth)[:, None], torch.cat([ha, hb], -1), view[:1])
        assert torch.allclose(ahead[:, 0], logits, atol=1e-5)
        traced = single_step(ens)(depth[:1], torch.cat([ha, hb], -1)[:1], view[:1])[0]
        assert torch.allclose(traced, logits[:1], atol=1e-4)


def test_an_ensemble_of_one_network_twice_runs_its_episodes(tmp_path):
    """The mean of equal logits is those logits, and of equal view scores their log-probabilities,
    whose argmax less the travel cost is the member's: the same answers, views and stops."""
    single, path = member(tmp_path, "one", 3)
    combine([path, path], tmp_path / "twice.pt")
    twice = checkpoint.load_model(tmp_path / "twice.pt")[0]
    rng = np.random.default_rng(0)
    meshes = [trimesh.creation.box(extents=rng.uniform(0.3, 1.0, 3)) for _ in range(2)]
    meshes += [trimesh.creation.cylinder(radius=0.3, height=h) for h in rng.uniform(0.4, 1.0, 2)]
    cams = [DepthCamera.from_mesh(m, CameraConfig(64, 64)) for m in meshes]
    starts = rng.uniform([0.3, -3], [2.8, 3], (4, 2))
    config = EpisodeConfig(max_views=5, entropy_threshold=0.5, travel_cost=0.3)
    steps = {}
    for name, model in (("single", single), ("twice", twice)):
        ep = Episode(model, config, ImitationPlanner(model))
        with torch.no_grad():
            steps[name] = run(ep, cams, starts)
    for s, t in zip(steps["single"], steps["twice"]):
        assert torch.allclose(s.probs, t.probs, atol=1e-5)
        assert torch.allclose(s.next_view, t.next_view, atol=1e-6) and torch.equal(s.done, t.done)
    views = torch.stack([s.next_view for s in steps["single"]])
    assert (views[1:] - views[:-1]).abs().sum() > 0  # the planner moved: the comparison saw it choose


def test_combine_and_load_refuse_what_does_not_fit(tmp_path, pair):
    _, pa = member(tmp_path, "a", 1)
    _, wide = member(tmp_path, "wide", 4, hidden_size=32)
    _, other = member(tmp_path, "other", 5, classes=("a", "b", "d"))
    cases = {"hidden_size": ([pa, wide], "model options differ"), "classes": ([pa, other], "classes"),
             "one member": ([pa], "2 to 8"), "an ensemble": ([pa, tmp_path / "both.pt"], "is an ensemble itself"),
             "a judge past the members": ([pa, pa], "judges \\[2\\]"), "a judge twice": ([pa, pa], "judges")}
    judges = {"a judge past the members": [2], "a judge twice": [1, 1]}
    for name, (paths, words) in cases.items():
        with pytest.raises(checkpoint.InputError, match=words):
            combine(paths, tmp_path / "out.pt", judges.get(name, []))
    assert not (tmp_path / "out.pt").exists()  # nothing written for a refusal
    ckpt = checkpoint.read(tmp_path / "both.pt")
    for bad in (1, 9, 2.0, "2"):
        checkpoint.save(tmp_path / "bad.pt", {**ckpt, "members": bad})
        with pytest.raises(checkpoint.CheckpointError, match="members must be an integer"):
            checkpoint.load_model(tmp_path / "bad.pt")
    for bad in ([5], "0", [0, 0]):
        checkpoint.save(tmp_path / "bad.pt", {**ckpt, "judges": bad})
        with pytest.raises(checkpoint.CheckpointError, match="judges"):
            checkpoint.load_model(tmp_path / "bad.pt")
    checkpoint.save(tmp_path / "three.pt", {**ckpt, "members": 3})  # weights of two for three members
    with pytest.raises(checkpoint.CheckpointError, match="weights do not fit"):
        checkpoint.load_model(tmp_path / "three.pt")
    with pytest.raises(checkpoint.CheckpointError, match="training continues a single one"):
        checkpoint.read_fitting(tmp_path / "both.pt", ModelConfig(**OPTIONS), ["a", "b", "c"])
    with pytest.raises(SystemExit) as exit_:
        main([str(pa), str(wide), "--out", str(tmp_path / "out.pt")])
    assert exit_.value.code == 2


def test_an_unknown_answer_fits_the_ensembles_state(pair, tmp_path):
    """open_set means are per member state side by side: (steps, classes, members x state)."""
    _, _, (ens, _, ckpt) = pair
    size = ens.config.state_size
    entry = {"score": "energy_mean", "means": torch.zeros(2, 3, size), "threshold": [-1.0, -1.5]}
    checkpoint.save(tmp_path / "fitted.pt", {**ckpt, "open_set": entry})
    assert checkpoint.load_model(tmp_path / "fitted.pt")[0].open_set["threshold"] == [-1.0, -1.5]
    half = {**entry, "means": torch.zeros(2, 3, size // 2)}
    checkpoint.save(tmp_path / "half.pt", {**ckpt, "open_set": half})
    with pytest.raises(checkpoint.CheckpointError, match="do not fit the model"):
        checkpoint.load_model(tmp_path / "half.pt")


@pytest.mark.parametrize("judges", [[1], []])
def test_the_node_reads_the_unknown_score_off_the_judges_logits(tmp_path, judges, dataset_cache, monkeypatch):
    """Through the recognizer's own path each view's energy is that of the judges' logits on the
    state it kept: member 1's alone, or the mean of both (the answer's own logits)."""
    from active_recognition.datasets import open_dataset
    from active_recognition.evaluation.camera_episodes import camera_runs
    from active_recognition.runtime.active_recognizer import ActiveRecognizer, SensingConfig

    monkeypatch.setenv("ACTIVE_RECOGNITION_CACHE", str(dataset_cache))
    ckpt = checkpoint.read(checkpoint.shipped("procedural"))
    louder = {k: 3 * v if k.startswith("classify.") else v for k, v in ckpt["model"].items()}
    checkpoint.save(tmp_path / "louder.pt", {**ckpt, "model": louder})
    combine([checkpoint.shipped("procedural"), tmp_path / "louder.pt"], tmp_path / "pair.pt", judges)
    core = ActiveRecognizer(tmp_path / "pair.pt", EpisodeConfig(3, 0.0), sensing=SensingConfig(use_size=False))
    test = open_dataset("procedural", None, "test", cache_dir=dataset_cache)
    runs = camera_runs(core, test, "procedural", "test", [0, 7], "virtual", seed=1, record=True)
    loud = checkpoint.load_model(tmp_path / "louder.pt")[0]
    size = loud.config.state_size
    for r in runs:
        states = torch.as_tensor(np.stack(r.states))
        with torch.no_grad():
            ens = core.model
            logits = loud.classify(states[:, size:]) if judges else ens.classify(states)
        np.testing.assert_allclose(r.energies, open_set.energy(logits.numpy()), rtol=1e-4)
        rec = open_set.Recorder(ens)  # open_set_fit's episodes on renders keep the same logits
        with torch.no_grad():
            rec(torch.zeros(1, 64, 64), states[:1], torch.zeros(1, 2))
            state = torch.as_tensor(rec.calls[0][1])
            kept = loud.classify(state[:, size:]) if judges else ens(torch.zeros(1, 64, 64), states[:1],
                                                                     torch.zeros(1, 2))[0]
        np.testing.assert_allclose(rec.calls[0][0], kept.numpy(), rtol=1e-5, atol=1e-6)
