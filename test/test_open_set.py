# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""The open-set scores and measures against independent reimplementations: Mahalanobis against
numpy on a toy Gaussian, AUROC against a brute-force pair count, FPR@95 on a hand-made case, and
the recorder against a plain rollout."""
import re

import numpy as np
import pytest
import torch
from conftest import sure_or_not

from active_recognition.argument_checks import InputError
from active_recognition.unknown import fit as open_set_fit, scores as open_set


def test_auroc_matches_a_pair_count_with_ties():
    rng = np.random.default_rng(0)
    known = rng.integers(0, 6, 40).astype(float)  # few values: many ties
    unknown = rng.integers(2, 9, 30).astype(float)
    pairs = [(u > k) + 0.5 * (u == k) for k in known for u in unknown]
    assert open_set.auroc(known, unknown) == pytest.approx(np.mean(pairs))
    assert open_set.auroc([0, 1], [2, 3]) == 1.0 and open_set.auroc([2, 3], [0, 1]) == 0.0
    with pytest.raises(InputError, match="empty"):
        open_set.auroc([], [1.0])


def test_fpr_at_95_on_a_hand_made_case():
    known = np.arange(1, 21, dtype=float)   # 95 % of 20 accepted: threshold 19
    unknown = np.array([0.5, 18.5, 19.0, 19.5, 30.0])  # three of five at or below 19
    assert open_set.threshold_at(known, 0.95) == 19.0
    assert open_set.fpr_at(known, unknown) == pytest.approx(3 / 5)
    assert open_set.threshold_at(known, 1.0) == 20.0
    with pytest.raises(InputError, match="share"):
        open_set.threshold_at(known, 0.0)


def test_mahalanobis_matches_numpy_on_a_toy_gaussian():
    rng = np.random.default_rng(1)
    cov = np.array([[2.0, 0.6, 0.0], [0.6, 1.0, 0.3], [0.0, 0.3, 0.5]])
    means = np.array([[0.0, 0.0, 0.0], [4.0, -1.0, 2.0]])
    labels = np.repeat([0, 1], 4000)
    x = means[labels] + rng.multivariate_normal(np.zeros(3), cov, len(labels))
    g = open_set.Gaussians.fit(x, labels, 2, shrink=0.0)
    np.testing.assert_allclose(g.precision, np.linalg.inv(cov), atol=0.08)  # the true one, nearly
    pooled = np.cov(np.concatenate([x[labels == c] - x[labels == c].mean(0) for c in (0, 1)]).T, bias=True)
    q = rng.normal(size=(5, 3))
    brute = [[(v - x[labels == c].mean(0)) @ np.linalg.inv(pooled) @ (v - x[labels == c].mean(0)) for c in (0, 1)]
             for v in q]
    np.testing.assert_allclose(g.distances(q), brute, rtol=1e-8)
    np.testing.assert_allclose(g.score(q), np.min(brute, 1), rtol=1e-8)
    with pytest.raises(InputError, match="class"):
        open_set.Gaussians.fit(x[:10], np.zeros(10, int), 2)


def test_prototype_is_the_cosine_distance_to_the_nearest_mean():
    g = open_set.Gaussians(np.array([[1.0, 0.0], [0.0, 2.0]]), np.eye(2))
    q = np.array([[3.0, 0.0], [1.0, 1.0], [-1.0, -1e-9], [0.0, 0.0]])
    brute = [1 - max(v @ m / (np.linalg.norm(v) * np.linalg.norm(m)) for m in g.means) if v.any() else 1.0 for v in q]
    np.testing.assert_allclose(g.cosine(q), brute, atol=1e-9)
    assert g.cosine(q)[0] == pytest.approx(0.0) and g.cosine(q)[2] == pytest.approx(1.0)


def test_energy_msp_and_running_mean():
    logits = np.array([[1000.0, 999.0, -5.0], [0.0, 0.0, 0.0]])  # large ones must not overflow
    np.testing.assert_allclose(open_set.energy(logits),
                               [-(1000 + np.log(1 + np.exp(-1) + np.exp(-1005))), -np.log(3)])
    np.testing.assert_allclose(open_set.msp([[0.7, 0.2, 0.1]]), [0.3])
    np.testing.assert_allclose(open_set.running_mean([[1.0, 3.0, 8.0]]), [[1.0, 2.0, 4.0]])


def test_scores_of_a_record_are_per_step():
    rng = np.random.default_rng(2)
    states = rng.normal(size=(30, 4, 5))
    labels = np.arange(30) % 3
    rec = {"probs": rng.dirichlet(np.ones(3), (30, 4)), "logits": rng.normal(size=(30, 4, 3)), "states": states}
    g = open_set.fit_steps(states, labels, 3)
    s = open_set.scores(rec, g)
    assert list(s) == list(open_set.SCORES) and all(v.shape == (30, 4) for v in s.values())
    np.testing.assert_allclose(s["mahalanobis"][:, 2], g[2].score(states[:, 2]))
    np.testing.assert_allclose(s["prototype_mean"][:, 1], (g[0].cosine(states[:, 0]) + g[1].cosine(states[:, 1])) / 2)
    assert "mahalanobis" not in open_set.scores(rec)


def test_recorder_keeps_the_rollouts_own_logits_and_states():
    from active_recognition.model.network import ModelConfig, RecurrentAttention

    torch.manual_seed(0)
    model = RecurrentAttention(ModelConfig(num_classes=3)).eval()
    rec = open_set.Recorder(model)
    size = model.config.image_size
    depth, hidden = torch.rand(2, size, size) * 255, model.init_hidden(2)
    seen = []
    for _ in range(3):  # one chunk of 2 objects, 3 steps, no mirror
        logits, _, hidden = rec(depth, hidden, torch.zeros(2, 2))
        seen.append((logits, hidden))
    rec.calls.append(rec.calls[0])
    with pytest.raises(RuntimeError, match="chunks"):  # 4 calls are no whole chunk of 3 steps
        rec.record(np.zeros((2, 3, 3)), chunk=2, steps=3, mirror=False)
    rec.calls.pop()
    out = rec.record(np.zeros((2, 3, 3)), chunk=2, steps=3, mirror=False)
    np.testing.assert_allclose(out["logits"][:, 1], seen[1][0].detach().numpy())
    np.testing.assert_allclose(out["states"][:, 2], seen[2][1].detach().numpy())


@pytest.mark.parametrize("readout", ["mean", "mean+mirror"])
def test_recorded_rollout_agrees_with_its_answers(readout):
    from active_recognition.datasets import open_dataset
    from active_recognition.datasets.shapes import Shapes
    from active_recognition.evaluation.evaluate import EvalConfig, sample_episodes
    from active_recognition.model.network import ModelConfig, RecurrentAttention
    from active_recognition.sensing.depth_layer import CameraConfig

    torch.manual_seed(0)
    model = RecurrentAttention(ModelConfig(num_classes=10, readout=readout)).eval()
    size = model.config.image_size
    shapes = Shapes(open_dataset("procedural", split="test", per_class=1), CameraConfig(size, size))
    cfg = EvalConfig(steps=3, shared=False)
    objects, starts = sample_episodes(4, len(shapes), 1, 0)
    ro, rec = open_set_fit.recorded_rollout("random", model, shapes, objects, starts, cfg, chunk=3)
    assert rec["logits"].shape == (4, 3, 10) and rec["states"].shape == (4, 3, model.config.state_size)
    own = torch.from_numpy(rec["logits"]).softmax(-1).numpy()
    if readout == "mean":  # the answer is the running mean of the recorded steps' own answers
        np.testing.assert_allclose(ro.probs, np.cumsum(own, 1) / np.arange(1, 4)[:, None], atol=1e-5)
    np.testing.assert_allclose(rec["probs"], ro.probs)


def test_the_benchmark_reports_every_score_by_views(tmp_path, capsys):
    """benchmarks/open_set_auroc.py end to end on the procedural benchmark, a few objects of each split."""
    import json

    from conftest import load_benchmark

    from active_recognition.datasets.unknowns import KINDS

    out = tmp_path / "open_set.json"
    load_benchmark("open_set_auroc").main(["--dataset", "procedural", "--objects", "4", "--fit-objects", "20",
                                           "--steps", "3", "--out", str(out)])
    last = json.loads(capsys.readouterr().out.strip().splitlines()[-1])
    assert set(last) == {"auroc", "fpr95", "known_rejected", "unknown_flagged", "known_accuracy", "chosen"}
    assert set(last["auroc"]) == set(open_set.SCORES) and all(len(v) == 3 for v in last["auroc"].values())
    assert all(0 <= x <= 1 for v in last["fpr95"].values() for x in v)
    record = json.loads(out.read_text())
    assert record["objects"] == {"known_test": 4, "unknown_test": 4, "known_val": 4, "unknown_val": 4, "fit": 20}
    assert set(record["unknown_flagged_by_kind"]) <= set(KINDS) and record["unknown_flagged_by_kind"]
    for s in open_set.SCORES:  # known accuracy with rejection is at most the closed-set one
        assert last["known_accuracy"][s]["3"] <= record["closed_set_accuracy"]["3"] + 1e-9
        assert last["known_rejected"][s]["3"] in {0, 0.25, 0.5, 0.75, 1.0}


def test_the_benchmark_keeps_its_episodes_in_the_elevation_band_asked(tmp_path, monkeypatch):
    """--min-elevation reaches every episode the benchmark runs (the fit's first): none from
    below the band, as a camera over a floor; the whole sphere by default."""
    from conftest import load_benchmark

    bench = load_benchmark("open_set_auroc")
    seen = []

    def stop(planner, model, shapes, objects, cfg, fixed_path):
        seen.append(cfg.limits.min_elevation)
        raise KeyboardInterrupt  # the episodes themselves are evaluate's, tested there

    monkeypatch.setattr(bench, "episodes", stop)
    for flags, band in (([], -90.0), (["--min-elevation", "0"], 0.0)):
        with pytest.raises(KeyboardInterrupt):
            bench.main(["--dataset", "procedural", "--objects", "4", "--fit-objects", "20",
                        "--out", str(tmp_path / "o.json"), *flags])
        assert seen[-1] == band


def test_the_recognizer_ends_unknown_past_its_energy_keeping_its_best_guess():
    """sensing.unknown_energy: the same episode ends with its answer at 0 (never unknown) and unknown
    with a threshold below its mean energy; the label and probability stay in the result."""
    from dataclasses import replace

    from active_recognition.runtime.active_recognizer import ActiveRecognizer, SensingConfig
    from active_recognition.sensing.reach import ViewLimits
    from active_recognition.simulation.depth_sensor import SimulatedCamera

    sim = SimulatedCamera()
    sim.load(dataset="procedural", split="test", index=0)
    ends = {}
    for threshold in (0.0, None, -1000.0):
        core = ActiveRecognizer(seed=1, limits=ViewLimits(0.0, 90.0))
        if threshold is None:  # just below this episode's own mean energy
            threshold = float(np.mean(ends[0.0][1])) - 1e-3
        core.reset(sensing=replace(SensingConfig(), unknown_energy=threshold))
        obs = None
        while not core.done:
            obs = core.observe(sim.capture(*core.requested_pose(sim.k))[0], sim.k)
            assert obs.status in ("classified", "recognized", "unsure", "unknown")
        ends[threshold] = obs, list(core.energies)
    (known, energies), *others = ends.values()
    assert known.status == sure_or_not(known.result(), core.confidence) and len(energies) == known.views
    for obs, same in others:
        assert obs.status == "unknown" and same == pytest.approx(energies)
        result = obs.result()
        assert result["status"] == "unknown" and result["label"] == known.label == obs.label
        assert result["probability"] == pytest.approx(float(known.probs.max())) and result["views"] == known.views
    with pytest.raises(InputError, match="unknown_energy"):
        SensingConfig(unknown_energy=1.0)


def stored_recognizer(tmp_path, name, means, threshold, sensing, score="prototype_mean", **episode):
    """An ActiveRecognizer on procedural.pt rewritten with a hand-made open_set entry."""
    from active_recognition.model import checkpoint
    from active_recognition.runtime.active_recognizer import ActiveRecognizer
    from active_recognition.sensing.reach import ViewLimits
    from active_recognition.unknown import fit as open_set_fit

    path = tmp_path / f"{name}.pt"
    entry = {"score": score, "means": torch.as_tensor(means, dtype=torch.float32),
             "threshold": threshold, "fitted_on": {"by": "hand"}}
    open_set_fit.store(checkpoint.shipped("procedural"), entry, path)
    from active_recognition.model.episode import EpisodeConfig
    core = ActiveRecognizer(str(path), EpisodeConfig(**episode), seed=1, limits=ViewLimits(0.0, 90.0))
    core.reset(sensing=sensing)
    return core


def episode_states(core, sim):
    """Run the recognizer's episode: (last observation, the recurrent state after each view)."""
    obs, states = None, []
    while not core.done:
        obs = core.observe(sim.capture(*core.requested_pose(sim.k))[0], sim.k)
        states.append(core.episode.hidden[0].numpy().copy())
    return obs, np.array(states)


def test_the_recognizer_ends_unknown_past_the_stored_prototype_threshold(tmp_path):
    """A checkpoint's open_set: states on a class mean end recognized; class means pointing
    away from every state end unknown, the best guess kept; the score is computed here anew."""
    from active_recognition.runtime.active_recognizer import SensingConfig
    from active_recognition.simulation.depth_sensor import SimulatedCamera

    sim = SimulatedCamera()
    sim.load(dataset="procedural", split="test", index=0)
    from active_recognition.model import checkpoint

    model, _, _ = checkpoint.load_model(checkpoint.shipped("procedural"))
    c, s = model.config.num_classes, model.config.state_size
    rng = np.random.default_rng(0)
    first = stored_recognizer(tmp_path, "random", rng.normal(size=(10, c, s)), 2.0, SensingConfig())
    obs, states = episode_states(first, sim)
    assert obs.status == sure_or_not(obs.result(), first.confidence) and len(states) == obs.views  # 2: none above
    on = rng.normal(size=(10, c, s))
    on[:len(states), 3] = states  # the episode's own states: class 3's means
    away = rng.normal(size=(10, c, s))
    away[:len(states)] = -states[:, None]  # every class's mean opposite the episode's state
    runs = {}
    for name, means, threshold in (("on", on, 0.05), ("away", away, 0.05), ("off", away, 0.05)):
        sensing = SensingConfig(unknown_threshold=0.0 if name == "off" else -1.0, hold_unknown=False)
        core = stored_recognizer(tmp_path, name, means, threshold, sensing)
        runs[name] = episode_states(core, sim)
        np.testing.assert_allclose(runs[name][1], states, atol=1e-5)  # the same episode each time
        unit = lambda v: v / np.maximum(np.linalg.norm(v, axis=-1, keepdims=True), 1e-12)  # noqa: E731
        expected = np.mean([1 - (unit(means[t]) @ unit(states[t])).max() for t in range(len(states))])
        assert np.mean(core.prototypes) == pytest.approx(expected, abs=1e-5)
        assert (expected > threshold) == (name != "on"), expected  # 0 on a mean, 2 opposite every one
    assert runs["on"][0].status == runs["off"][0].status == sure_or_not(runs["on"][0].result(), core.confidence)
    unknown = runs["away"][0]
    assert unknown.status == "unknown" and unknown.label == obs.label
    assert unknown.result()["probability"] == pytest.approx(float(obs.probs.max()))
    with pytest.raises(InputError, match="unknown_threshold"):
        SensingConfig(unknown_threshold=-0.5)
    # hold_unknown (the default): the confident answer that looks unknown does not end the episode;
    # an entropy threshold above log C makes every answer confident, so an unheld episode ends at once
    ends = {}
    for name, means, hold in (("held", away, True), ("unheld", away, False), ("known", on, True)):
        core = stored_recognizer(tmp_path, name, means, 0.05, SensingConfig(hold_unknown=hold),
                                 entropy_threshold=5.0)
        ends[name] = episode_states(core, sim)
    assert ends["unheld"][0].views == ends["known"][0].views == 1 and ends["known"][0].status == "recognized"
    assert ends["unheld"][0].status == "unknown"
    held, held_states = ends["held"]
    assert held.status == "unknown" and held.views == 10  # max_views: it never looked known
    np.testing.assert_allclose(held_states[:len(states)], states, atol=1e-5)  # the same views meanwhile
    # a threshold per number of views: the running score (2: opposite every mean) is above the
    # first view's 0.05 and at most the later ones' 2.0, so the hold waits one view, then it ends known
    core = stored_recognizer(tmp_path, "steps", away, [0.05, 2.0], SensingConfig(), entropy_threshold=5.0)
    stepped = episode_states(core, sim)[0]
    assert core.open_set_threshold() == 2.0 and stepped.views == 2 and stepped.status == "recognized"


def test_held_stops_end_at_the_first_confident_step_that_looks_known():
    """open_set.held_stops, the recognizer's hold measured after the fact: an episode ends at its
    first step with entropy below the threshold and a score at most the threshold, else last."""
    from active_recognition.unknown.scores import held_stops
    sure, unsure = [0.98, 0.01, 0.01], [0.4, 0.3, 0.3]
    probs = np.array([[unsure, sure, sure, sure],    # confident from step 2, known-looking from 3
                      [sure, sure, sure, sure],      # confident and known-looking at once
                      [sure, unsure, sure, sure]])   # never known-looking: its last step
    scores = np.array([[0.9, 0.5, 0.1, 0.1], [0.1, 0.1, 0.1, 0.1], [0.9, 0.9, 0.9, 0.9]])
    np.testing.assert_array_equal(held_stops(probs, scores, 0.2, 0.3), [3, 1, 4])
    np.testing.assert_array_equal(held_stops(probs, scores, 0.2, 1.0), [2, 1, 1])  # nothing held


@pytest.mark.parametrize("change, message", [
    (lambda e: e.update(means=e["means"][:, :3]), "do not fit"),
    (lambda e: e.update(means=e["means"][0]), "float tensor"),
    (lambda e: e.update(threshold=3.0), "threshold"),
    (lambda e: e.update(threshold=torch.tensor([0.3, 0.0])), "threshold"),
    (lambda e: e.update(threshold=[]), "threshold"),
    (lambda e: e.update(score="msp_mean"), "score"),
    (lambda e: e.update(score="energy_mean", threshold=[-3.0, float("nan")]), "energy_mean must be a finite"),
    (lambda e: e.pop("means"), "means")])
def test_a_checkpoint_with_a_bad_open_set_is_refused_by_name(tmp_path, change, message):
    from active_recognition.model import checkpoint
    from active_recognition.model.checkpoint import CheckpointError

    ckpt = checkpoint.read(checkpoint.shipped("procedural"))
    ckpt.pop("format")
    c, s = len(ckpt["classes"]), checkpoint.build_model(ckpt).config.state_size
    entry = {"score": "prototype_mean", "means": torch.zeros(4, c, s), "threshold": 0.3, "fitted_on": {}}
    checkpoint.save(tmp_path / "good.pt", {**ckpt, "open_set": dict(entry)})
    assert checkpoint.load_model(tmp_path / "good.pt")[0].open_set["threshold"] == [0.3]  # one for all steps
    checkpoint.save(tmp_path / "steps.pt", {**ckpt, "open_set": {**entry, "threshold": torch.tensor([0.5, 0.25])}})
    assert checkpoint.load_model(tmp_path / "steps.pt")[0].open_set["threshold"] == [0.5, 0.25]
    change(entry)
    checkpoint.save(tmp_path / "bad.pt", {**ckpt, "open_set": entry})
    with pytest.raises(CheckpointError, match=message):
        checkpoint.load_model(tmp_path / "bad.pt")


def test_an_energy_mean_open_set_reads_the_views_energies(tmp_path):
    """A checkpoint whose open_set score is energy_mean: the episode's mean energy against its
    threshold decides, whatever the class means say (random here); a positive unknown_threshold
    still sets a prototype_mean threshold."""
    from active_recognition.model import checkpoint
    from active_recognition.runtime.active_recognizer import SensingConfig
    from active_recognition.simulation.depth_sensor import SimulatedCamera

    sim = SimulatedCamera()
    sim.load(dataset="procedural", split="test", index=0)
    model = checkpoint.load_model(checkpoint.shipped("procedural"))[0]
    c, s = model.config.num_classes, model.config.state_size
    means = np.random.default_rng(0).normal(size=(10, c, s))
    plain = stored_recognizer(tmp_path, "plain", means, 2.0, SensingConfig(hold_unknown=False))
    obs, _ = episode_states(plain, sim)
    mean_energy = float(np.mean(plain.energies))
    assert obs.status == sure_or_not(obs.result(), plain.confidence) and len(plain.energies) == obs.views
    assert np.isfinite(mean_energy)
    ends = {}
    for name, threshold, sensing in (("below", mean_energy - 0.5, SensingConfig(hold_unknown=False)),
                                     ("above", mean_energy + 0.5, SensingConfig(hold_unknown=False)),
                                     ("override", mean_energy - 0.5, SensingConfig(unknown_threshold=2.0,
                                                                                   hold_unknown=False))):
        core = stored_recognizer(tmp_path, name, means, threshold, sensing, score="energy_mean")
        ends[name] = episode_states(core, sim)[0]
        assert core.open_set_scores() is (core.energies if name != "override" else core.prototypes)
    assert ends["below"].status == "unknown" and ends["below"].label == obs.label  # its energy is above
    answer = sure_or_not(ends["above"].result(), core.confidence)  # not unknown
    assert ends["above"].status == answer and ends["override"].status == answer
    # the hold reads each view's energy as it is taken: every answer confident (entropy 5), an energy
    # threshold below any energy holds from the first view to max_views; one above any ends at once
    held = {}
    for name, threshold in (("held", -1000.0), ("free", 1000.0)):
        core = stored_recognizer(tmp_path, f"h{name}", means, threshold, SensingConfig(), score="energy_mean",
                                 entropy_threshold=5.0)
        held[name] = episode_states(core, sim)[0]
    assert held["held"].status == "unknown" and held["held"].views == 10
    assert held["free"].status == "recognized" and held["free"].views == 1


def test_open_set_fit_stores_means_of_training_states_and_a_val_threshold(tmp_path, dataset_cache, monkeypatch,
                                                                          capsys):
    """fit on a few procedural objects: means (steps, C, S) equal to the class means of states
    recorded anew, a threshold that accepts the asked share of the val objects' end scores, and a
    checkpoint that loads (weights_only) with it."""
    from active_recognition.datasets import open_splits, subset_with_every_class
    from active_recognition.datasets.shapes import Shapes
    from active_recognition.evaluation.evaluate import EvalConfig
    from active_recognition.model import checkpoint
    from active_recognition.sensing.depth_layer import CameraConfig
    from active_recognition.unknown import fit as open_set_fit

    monkeypatch.setenv("ACTIVE_RECOGNITION_CACHE", str(dataset_cache))
    path = checkpoint.shipped("procedural")
    entry = open_set_fit.fit(path, "procedural", objects=20, known_rate=0.8, steps=3, val_objects=10)
    model, classes, _ = checkpoint.load_model(path)
    assert tuple(entry["means"].shape) == (3, len(classes), model.config.state_size)
    from active_recognition.model.episode import ROBOT  # the answer is fitted for the node's episodes

    cfg = EvalConfig(dataset="procedural", split="val", steps=3, size=False, shared=False,
                     entropy_threshold=ROBOT.entropy_threshold, travel_cost=ROBOT.travel_cost)
    size = model.config.image_size
    camera = CameraConfig(size, size, radius=model.config.radius)
    train = Shapes(open_splits("procedural", None, ("train",))["train"], camera)
    objects = subset_with_every_class(train.labels, 20, 0)
    planner, fixed_path = open_set_fit.node_planner("auto", model, checkpoint.read(path))  # the node's
    assert entry["fitted_on"]["planner"] == planner
    ro, rec = open_set_fit.episodes(planner, model, train, objects, cfg, fixed_path)
    c = int(ro.labels[0])
    np.testing.assert_allclose(entry["means"][:, c].numpy(), rec["states"][ro.labels == c].mean(0), rtol=1e-5)
    fitted = entry["fitted_on"]
    assert fitted["val_known"] == fitted["val_unknown"] == 10 and fitted["val_known_rejected"] <= 0.2
    open_set_fit.store(path, entry, tmp_path / "stored.pt")
    stored = torch.load(tmp_path / "stored.pt", weights_only=True)["open_set"]
    assert stored["threshold"] == entry["threshold"] and torch.equal(stored["means"], entry["means"])
    assert checkpoint.load_model(tmp_path / "stored.pt")[0].open_set["threshold"] == entry["threshold"]
    # the command line fits the same (seeded) and says so, with no size term by default
    open_set_fit.main(["--dataset", "procedural", "--objects", "20", "--known-rate", "0.8", "--steps", "3",
                       "--val-objects", "10", "--out", str(tmp_path / "main.pt")])
    assert checkpoint.load_model(tmp_path / "main.pt")[0].open_set["threshold"] == entry["threshold"]
    assert "size weight 0;" in capsys.readouterr().err


def test_open_set_fit_on_energy_mean_holds_thresholds_of_the_val_energies(dataset_cache, monkeypatch):
    """fit --score energy_mean: its thresholds are held_thresholds (floor -inf) of the val
    episodes' running mean energies, recomputed here from their logits; a bad score is refused."""
    from active_recognition.datasets import open_splits
    from active_recognition.datasets.shapes import Shapes
    from active_recognition.evaluation.evaluate import EvalConfig
    from active_recognition.model import checkpoint
    from active_recognition.model.episode import ROBOT
    from active_recognition.sensing.depth_layer import CameraConfig
    from active_recognition.unknown import fit as open_set_fit, scores as open_set

    monkeypatch.setenv("ACTIVE_RECOGNITION_CACHE", str(dataset_cache))
    path = checkpoint.shipped("procedural")
    entry = open_set_fit.fit(path, "procedural", objects=20, known_rate=0.8, steps=3, val_objects=10,
                             score="energy_mean")
    assert entry["score"] == entry["fitted_on"]["score"] == "energy_mean" and all(t < 0 for t in entry["threshold"])
    model = checkpoint.load_model(path)[0]
    cfg = EvalConfig(dataset="procedural", split="val", steps=3, size=False, shared=False,
                     entropy_threshold=ROBOT.entropy_threshold, travel_cost=ROBOT.travel_cost)
    size = model.config.image_size
    val = Shapes(open_splits("procedural", None, ("val",))["val"], CameraConfig(size, size, radius=model.config.radius))
    pick = np.sort(np.random.default_rng(0).permutation(len(val))[:10])
    planner, fixed_path = open_set_fit.node_planner("auto", model, checkpoint.read(path))
    ro, rec = open_set_fit.episodes(planner, model, val, pick, cfg, fixed_path)
    energies = -np.log(np.exp(rec["logits"].astype(float)).sum(-1))  # each step's, by hand
    expected = open_set.held_thresholds(ro.probs, np.cumsum(energies, 1) / np.arange(1, 4), cfg.entropy_threshold,
                                        0.8, floor=-np.inf)
    np.testing.assert_allclose(entry["threshold"], expected, rtol=1e-6)
    with pytest.raises(InputError, match="score must be one of"):
        open_set_fit.fit(path, "procedural", objects=20, steps=3, val_objects=10, score="msp")


@pytest.mark.parametrize("score, top", [("prototype_mean", 2.0), ("energy_mean", 0.0)])
def test_the_benchmark_reports_a_stored_operating_point(tmp_path, capsys, score, top):
    """A checkpoint with its own open_set: the last JSON line also holds `stored`; at the largest
    threshold (2: 1 - a cosine never exceeds it; 0 for an energy, -log sum exp of a trained
    model's logits, where every prototype score would be above it) nothing is rejected and the
    known accuracy is the closed-set one."""
    import json

    from conftest import load_benchmark

    from active_recognition.model import checkpoint
    from active_recognition.unknown import fit as open_set_fit

    model = checkpoint.load_model(checkpoint.shipped("procedural"))[0]
    means = torch.rand(3, model.config.num_classes, model.config.state_size, generator=torch.Generator().manual_seed(0))
    open_set_fit.store(checkpoint.shipped("procedural"), {"score": score, "means": means,
                                                          "threshold": top, "fitted_on": {}}, tmp_path / "s.pt")
    out = tmp_path / "open_set.json"
    load_benchmark("open_set_auroc").main(["--dataset", "procedural", "--checkpoint", str(tmp_path / "s.pt"),
                                           "--objects", "4", "--fit-objects", "20", "--steps", "3", "--out", str(out)])
    last = json.loads(capsys.readouterr().out.strip().splitlines()[-1])
    stored, record = last["stored"], json.loads(out.read_text())
    assert set(stored["known_rejected"]) == {"3", "end", "unheld"} and stored["threshold"] == [top] * 3
    assert all(v == 0 for key in ("known_rejected", "unknown_flagged") for v in stored[key].values())
    # nothing above it: the hold never holds, so each episode answers at its entropy stop
    assert stored["known_accuracy"]["3"] == stored["known_accuracy"]["end"] == stored["known_accuracy"]["unheld"]
    assert set(record["compared"]) == {"planner", "auroc", "fpr95", "stored"}
    assert record["compared"]["planner"] == "random"
    assert len(record["compared"]["auroc"]) == 3


def test_held_thresholds_reject_at_most_the_budget_at_every_cut_and_no_lower_one_would():
    """open_set.held_thresholds against held_stops, brute force: cut after any k views, the
    known episodes ending unknown (running score at the held end above its step's threshold) are
    at most (1 - rate) N, and lowering step k's threshold to the next score below it breaks
    that (each threshold is the least the budget allows), while the earlier ones stay put."""
    from active_recognition.unknown.scores import held_stops, held_thresholds
    rng = np.random.default_rng(0)
    probs = rng.dirichlet(np.full(4, 0.3), size=(200, 6))
    scores = np.cumsum(rng.random((200, 6)), 1) / np.arange(1, 7)

    def rejected(thr, k):
        ends = held_stops(probs[:, :k], scores[:, :k], 0.5, thr[:k])
        return int((scores[np.arange(200), ends - 1] > thr[ends - 1]).sum())

    for rate in (0.8, 0.95, 0.99):
        thr = held_thresholds(probs, scores, 0.5, rate)
        budget = int(np.floor((1 - rate) * 200 + 1e-9))
        for k in range(1, 7):
            assert rejected(thr, k) <= budget
            below = scores[:, k - 1][scores[:, k - 1] < thr[k - 1]]
            if len(below):
                lower = thr.copy()
                lower[k - 1] = below.max()
                assert rejected(lower, k) > budget
    with pytest.raises(InputError, match="share"):
        held_thresholds(probs, scores, 0.5, 1.5)
    # a score of any sign (energy_mean), floor -inf: the thresholds move with the scores
    for rate in (0.8, 0.95):
        np.testing.assert_allclose(held_thresholds(probs, scores - 10.0, 0.5, rate, floor=-np.inf),
                                   held_thresholds(probs, scores, 0.5, rate) - 10.0)


def test_step_thresholds_run_on_past_their_last_step():
    from active_recognition.unknown.scores import step_thresholds
    np.testing.assert_array_equal(step_thresholds(0.3, 3), [0.3, 0.3, 0.3])
    np.testing.assert_array_equal(step_thresholds([0.5, 0.4], 4), [0.5, 0.4, 0.4, 0.4])
    np.testing.assert_array_equal(step_thresholds(np.array([0.5, 0.4, 0.3]), 2), [0.5, 0.4])


def test_camera_band_splits_the_gap_into_parts_that_add_up(tmp_path, capsys):
    """benchmarks/camera_band.py on three made-up records: the band's and the camera's points
    add up to the whole gap, each the difference of its two records; a band file run on the
    whole sphere is refused by name."""
    import json

    from conftest import load_benchmark

    bench = load_benchmark("camera_band")

    def stored(acc, elevation=-90.0, key="stored"):
        return {"min_elevation": elevation, "objects": {"known_test": 7}, "checkpoint": "m.pt",
                "planner": "imitation", key: {"known_accuracy": dict(zip(("3", "6", "9", "end"), acc))}}

    files = {"sphere": stored((0.9, 0.92, 0.93, 0.93)), "band": stored((0.88, 0.9, 0.905, 0.9), 0.0),
             "camera": stored((0.87, 0.875, 0.9, 0.9), key="cut") | {"objects": 5}}
    for name, rec in files.items():
        (tmp_path / f"{name}.json").write_text(json.dumps(rec))
    flags = [f"--{n}={tmp_path / n}.json" for n in files]
    bench.main([*flags, "--out", str(tmp_path / "o.json")])
    lost = json.loads(capsys.readouterr().out.strip().splitlines()[-1])
    assert lost["band"] == {"3": 2.0, "6": 2.0, "9": 2.5} and lost["camera"] == {"3": 1.0, "6": 2.5, "9": 0.5}
    for v in ("3", "6", "9"):
        assert lost["band"][v] + lost["camera"][v] == pytest.approx(lost["total"][v])
    assert json.loads((tmp_path / "o.json").read_text())["objects"] == {"sphere": 7, "band": 7, "camera": 5}
    wrong = {"band": (stored((0.88, 0.9, 0.905, 0.9)), "--band .* not run with --min-elevation 0"),
             "sphere": (stored((0.9, 0.92, 0.93, 0.93), 0.0), "--sphere .* not a whole-sphere run"),
             "camera": (files["camera"] | {"checkpoint": "other.pt"},
                        "different checkpoints: --sphere 'm.pt', --band 'm.pt', --camera 'other.pt'")}
    for name, (rec, message) in wrong.items():
        (tmp_path / f"{name}.json").write_text(json.dumps(rec))
        with pytest.raises(SystemExit):
            bench.main([*flags, "--out", ""])
        assert re.search(message, capsys.readouterr().err), name
        (tmp_path / f"{name}.json").write_text(json.dumps(files[name]))
