# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""The `unknown` answer's size term: a known size unlike every class's is evidence of an unknown
object (size_prior.SizePrior.surprise, open_set.size_term, the recognizer's threshold, the fit)."""
import math
from dataclasses import replace
from types import SimpleNamespace

import numpy as np
import pytest
import torch

from active_recognition.argument_checks import InputError
from active_recognition.model import checkpoint
from active_recognition.model.size_prior import SizePrior
from active_recognition.unknown import fit as open_set_fit, scores as open_set

PRIOR = SizePrior(log_median=[math.log(0.5), math.log(2.0)], log_scale=[0.2, 0.4], log_lo=-3.0, log_hi=3.0)


def log_normal_density(x, median, scale):
    """The density of log size x under N(log median, scale), written out."""
    return math.exp(-0.5 * ((x - math.log(median)) / scale) ** 2) / (scale * math.sqrt(2 * math.pi))


def test_surprise_is_minus_the_best_class_log_density_of_the_log_size():
    sizes = [0.5, 1.0, 2.0, 0.05, 30.0]
    expected = [-math.log(max(log_normal_density(math.log(s), 0.5, 0.2), log_normal_density(math.log(s), 2.0, 0.4)))
                for s in sizes]
    np.testing.assert_allclose(PRIOR.surprise(sizes), expected, rtol=1e-9)
    # at a class's median: that class's peak, -log(1 / (scale sqrt(2 pi)))
    assert PRIOR.surprise(0.5)[0] == pytest.approx(math.log(0.2 * math.sqrt(2 * math.pi)))
    # far from every class it grows as the square of the distance in log units
    assert PRIOR.surprise(0.01)[0] > PRIOR.surprise(0.1)[0] > PRIOR.surprise(0.5)[0]
    for bad in (0.0, -1.0, float("nan")):
        with pytest.raises(InputError, match="object size"):
            PRIOR.surprise(bad)


def test_the_size_term_is_its_weight_times_the_surprise_and_nothing_without_one_of_them():
    model = SimpleNamespace(size_prior=PRIOR, open_set={"size_weight": 1.5})
    assert open_set.size_term(model, 0.1) == pytest.approx(1.5 * PRIOR.surprise(0.1)[0])
    assert open_set.size_term(model, None) == 0.0  # the size not used
    assert open_set.size_term(SimpleNamespace(size_prior=None, open_set={"size_weight": 1.5}), 0.1) == 0.0
    assert open_set.size_term(SimpleNamespace(size_prior=PRIOR, open_set={}), 0.1) == 0.0  # fitted before the term
    assert open_set.size_term(SimpleNamespace(size_prior=PRIOR, open_set=None), 0.1) == 0.0


def test_own_thresholds_carry_the_term_with_a_size_and_the_plain_ones_without():
    """With a size: those fitted with the term, less it; without one (or with no prior): those
    fitted without the term where the checkpoint has them, else its only ones."""
    entry = {"threshold": [-2.0, -3.0], "threshold_no_size": [-1.0, -1.5], "size_weight": 2.0}
    model = SimpleNamespace(size_prior=PRIOR, open_set=entry)
    term = 2.0 * PRIOR.surprise(0.1)[0]
    np.testing.assert_allclose(open_set.own_thresholds(model, 0.1), [-2.0 - term, -3.0 - term])
    assert open_set.own_thresholds(model, None) == [-1.0, -1.5]
    assert open_set.own_thresholds(SimpleNamespace(size_prior=None, open_set=entry), 0.1) == [-1.0, -1.5]
    assert open_set.own_thresholds(SimpleNamespace(size_prior=PRIOR, open_set={"threshold": [-2.0]}), 0.1) == [-2.0]


def sized_checkpoint(tmp_path, threshold, weight, **extra):
    """procedural.pt with a size prior and an energy_mean open_set of one threshold and `weight`."""
    ckpt = checkpoint.read(checkpoint.shipped("procedural"))
    ckpt.pop("format")
    model = checkpoint.build_model(ckpt)
    c, s = model.config.num_classes, model.config.state_size
    prior = SizePrior(log_median=[0.0] * c, log_scale=[0.2] * c, log_lo=-3.0, log_hi=3.0)
    path = tmp_path / f"sized_{weight}.pt"
    checkpoint.save(path, {**ckpt, "size_prior": prior.to_dict(), "open_set": {
        "score": "energy_mean", "means": torch.zeros(1, c, s), "threshold": [threshold], "fitted_on": {},
        "size_weight": weight, **extra}})
    return path


def test_the_recognizer_lowers_its_threshold_by_the_size_term_where_it_uses_the_size(tmp_path):
    """The same 10-view episode (no stop, no hold) of an object told to be 0.1 m, where every class
    is about 1 m: its mean energy sits just below the threshold, so it ends recognized with the size
    unused or a weight of 0, and unknown once the size term lifts it past the threshold."""
    from active_recognition.model.episode import EpisodeConfig
    from active_recognition.runtime.active_recognizer import ActiveRecognizer, SensingConfig
    from active_recognition.sensing.reach import ViewLimits
    from active_recognition.simulation.depth_sensor import SensorConfig, SimulatedCamera

    sim = SimulatedCamera(SensorConfig(object_size=0.1))
    sim.load(dataset="procedural", split="test", index=0)

    def run(path, use_size):
        core = ActiveRecognizer(str(path), EpisodeConfig(10, 0.0), seed=1, limits=ViewLimits(0.0, 90.0))
        core.reset(view=core.initial_views[0], sensing=replace(SensingConfig(), object_size=0.1, use_size=use_size,
                                                               hold_unknown=False))
        obs = None
        while not core.done:
            obs = core.observe(sim.capture(*core.requested_pose(sim.k))[0], sim.k)
        return core, obs

    probe, _ = run(sized_checkpoint(tmp_path, 0.0, 0.0), True)
    threshold = float(np.mean(probe.energies)) + 0.5  # the episode's energy is 0.5 below it
    surprise = float(SizePrior(log_median=[0.0], log_scale=[0.2], log_lo=-3.0, log_hi=3.0).surprise(0.1)[0])
    weight = 1.0 / surprise  # a term of 1: past the 0.5 margin
    ends = {}
    plain = {"threshold_no_size": [threshold - 1.0]}  # without the size, these: 0.5 above it
    for name, w, use_size, extra, expected in (
            ("no weight", 0.0, True, {}, threshold), ("size unused", weight, False, {}, threshold),
            ("size term", weight, True, {}, threshold - 1.0), ("plain ones", weight, False, plain, threshold - 1.0),
            ("plain ones unused", weight, True, {"threshold_no_size": [threshold + 5.0]}, threshold - 1.0)):
        core, obs = run(sized_checkpoint(tmp_path, threshold, w, **extra), use_size)
        assert core.energies == pytest.approx(probe.energies)  # the same images, the same energies
        assert core.open_set_threshold() == pytest.approx(expected)
        ends[name] = obs.status
    # entropy_threshold 0: never sure, so an answer that is not unknown is unsure
    assert ends == {"no weight": "unsure", "size unused": "unsure", "size term": "unknown",
                    "plain ones": "unknown", "plain ones unused": "unknown"}


@pytest.mark.parametrize("weight, extra, message", [
    (-0.5, {}, "size_weight"), (float("nan"), {}, "size_weight"), ("1", {}, "size_weight"),
    (1.0, {"threshold_no_size": [-2.0, float("nan")]}, "threshold_no_size"),
    (1.0, {"threshold_no_size": []}, "threshold_no_size")])
def test_a_checkpoint_with_a_bad_size_term_is_refused_by_name(tmp_path, weight, extra, message):
    from active_recognition.model.checkpoint import CheckpointError

    with pytest.raises(CheckpointError, match=message):
        checkpoint.load_model(sized_checkpoint(tmp_path, -3.0, weight, **extra))
    good = checkpoint.load_model(sized_checkpoint(tmp_path, -3.0, 1.0, threshold_no_size=torch.tensor([-2.0, -2.5])))
    assert good[0].open_set["threshold_no_size"] == [-2.0, -2.5]


def test_the_fit_keeps_the_weight_that_flags_the_most_val_unknowns():
    """Energies alike for known and unknown val episodes, sizes not: the term must be weighed in to
    tell them; with every size alike no weight flags more and the least (0) is kept."""
    rng = np.random.default_rng(0)
    n, steps = 200, 4
    probs = np.full((n, steps, 3), 1 / 3)  # never confident: every episode runs to its end
    known = (probs, open_set.running_mean(rng.normal(-5, 1, (n, steps))))
    unknown = (probs, open_set.running_mean(rng.normal(-5, 1, (n, steps))))
    apart = {"known": np.full(n, 0.5), "unknown": np.full(n, 0.05)}  # the unknowns all far smaller than a class
    weight, table = open_set_fit.choose_size_weight(PRIOR, known, unknown, apart, 0.5, 0.97, (0.0, 1.0, 4.0))
    assert weight > 0 and table[str(weight)]["val_unknown_flagged"] > 0.9 > 0.1 > table["0.0"]["val_unknown_flagged"]
    assert all(row["val_known_rejected"] <= 0.03 for row in table.values())
    alike = {"known": np.full(n, 0.5), "unknown": np.full(n, 0.5)}
    weight, table = open_set_fit.choose_size_weight(PRIOR, known, unknown, alike, 0.5, 0.97, (0.0, 1.0, 4.0))
    assert weight == 0.0 and len({row["val_unknown_flagged"] for row in table.values()}) == 1
    with pytest.raises(InputError, match="size_weights"):
        open_set_fit.fit(checkpoint.shipped("procedural"), "procedural", size_weights=(-1.0,))


def test_the_fit_stores_the_terms_thresholds_and_the_plain_ones_beside(tmp_path, dataset_cache, monkeypatch):
    """fit --score energy_mean through a camera with --size-weights: the val episodes' running
    energies (made up here, through_camera stubbed) plus the chosen weight x surprise give the
    thresholds; the plain energies give threshold_no_size; the checkpoint stores and loads both."""
    monkeypatch.setenv("ACTIVE_RECOGNITION_CACHE", str(dataset_cache))
    path = sized_checkpoint(tmp_path, -3.0, 0.0)
    prior = checkpoint.load_model(path)[0].size_prior
    rng = np.random.default_rng(0)
    n, steps = 60, 3
    probs = np.full((n, steps, 10), 0.1)  # never confident: every episode runs to its end
    known = (probs, open_set.running_mean(rng.normal(-5, 1, (n, steps))))
    unknown = (probs, open_set.running_mean(rng.normal(-5, 1, (n, steps))))
    sizes = {"known": np.full(n, 1.0), "unknown": np.full(n, 0.1)}  # every class is about 1 m

    def stub(path, planner, dataset, root, preset, steps, seed, size, train, val, unknown_group, rendered, score):
        return rendered, known, unknown, {"camera_stubbed": True}, sizes

    monkeypatch.setattr(open_set_fit, "through_camera", stub)
    entry = open_set_fit.fit(path, "procedural", objects=20, known_rate=0.9, steps=steps, val_objects=10,
                             camera="realsense", score="energy_mean", size_weights=(0.0, 1.0))
    assert entry["size_weight"] == 1.0 and entry["fitted_on"]["size_weights"]["1.0"]["val_unknown_flagged"] > 0.9
    shifted = open_set_fit.with_size(known, prior, sizes["known"], 1.0)
    np.testing.assert_allclose(entry["threshold"], open_set.held_thresholds(*shifted, 0.5, 0.9, -np.inf))
    np.testing.assert_allclose(entry["threshold_no_size"], open_set.held_thresholds(*known, 0.5, 0.9, -np.inf))
    open_set_fit.store(path, entry, tmp_path / "stored.pt")
    stored = checkpoint.load_model(tmp_path / "stored.pt")[0].open_set
    assert stored["size_weight"] == 1.0 and stored["threshold_no_size"] == pytest.approx(entry["threshold_no_size"])
    plain = open_set_fit.fit(path, "procedural", objects=20, known_rate=0.9, steps=steps, val_objects=10,
                             camera="realsense", score="energy_mean")  # the default: no size term
    assert "size_weight" not in plain and "threshold_no_size" not in plain
