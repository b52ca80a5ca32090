# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""The size prior: what an object's size says of its class, from the mesh files to the answer."""
import math

import numpy as np
import pytest
import torch
from test_datasets import CUBE_QUADS, CUBE_V, write_off

from active_recognition.argument_checks import InputError
from active_recognition.datasets import open_dataset
from active_recognition.datasets.modelnet import INCH
from active_recognition.datasets.shapes import Shapes
from active_recognition.model import checkpoint, size_prior
from active_recognition.model.episode import Episode, EpisodeConfig
from active_recognition.model.network import ModelConfig, RecurrentAttention
from active_recognition.model.size_prior import MIN_SCALE, SizePrior, fit
from active_recognition.runtime.active_recognizer import ActiveRecognizer, SensingConfig
from active_recognition.sensing.depth_layer import CameraConfig


def sample(seed=0):
    rng = np.random.default_rng(seed)
    labels = np.repeat([0, 1, 2], [40, 25, 30])
    sizes = np.exp(np.array([-0.4, 0.3, 0.9])[labels] + rng.normal(0, [0.1, 0.25, 0.2])[labels])
    return sizes, labels


def test_the_fit_is_each_class_median_and_scaled_absolute_deviation_of_log_sizes():
    sizes, labels = sample()
    prior = fit(sizes, labels, 3, weight=0.5, outlier=0.1)
    for c in range(3):
        logs = sorted(math.log(s) for s, y in zip(sizes, labels) if y == c)
        mid = len(logs) // 2
        median = logs[mid] if len(logs) % 2 else (logs[mid - 1] + logs[mid]) / 2
        deviations = sorted(abs(x - median) for x in logs)
        mad = deviations[mid] if len(logs) % 2 else (deviations[mid - 1] + deviations[mid]) / 2
        assert prior.log_median[c] == pytest.approx(median)
        assert prior.log_scale[c] == pytest.approx(max(MIN_SCALE, 1.4826 * mad))
    assert prior.log_lo == pytest.approx(math.log(sizes.min()) - 1)
    assert prior.log_hi == pytest.approx(math.log(sizes.max()) + 1)
    # a class whose sizes all agree keeps the floor, so its likelihood stays finite
    same = fit([2.0, 2.0, 1.0, 1.5], [0, 0, 1, 1], 2)
    assert same.log_scale[0] == MIN_SCALE


def test_the_likelihood_is_a_density_over_log_size_and_matches_the_formula():
    sizes, labels = sample(1)
    prior = fit(sizes, labels, 3, outlier=0.05)
    grid = np.linspace(prior.log_lo, prior.log_hi, 20001)
    density = prior.log_likelihood(np.exp(grid)).exp().numpy()          # (N, C), over log size
    mass = ((density[1:] + density[:-1]) / 2 * np.diff(grid)[:, None]).sum(0)
    np.testing.assert_allclose(mass, 1.0, atol=2e-3)  # normal inside the range + the uniform part
    s, c = 1.7, 1
    z = (math.log(s) - prior.log_median[c]) / prior.log_scale[c]
    expect = math.log(0.95 * math.exp(-z * z / 2) / (prior.log_scale[c] * math.sqrt(2 * math.pi))
                      + 0.05 / (prior.log_hi - prior.log_lo))
    assert prior.log_likelihood([s])[0, c].item() == pytest.approx(expect)


def test_apply_weighs_the_answer_by_the_likelihood_to_the_weight_and_renormalises():
    sizes, labels = sample(2)
    probs = torch.tensor([[0.5, 0.3, 0.2], [0.1, 0.1, 0.8]])
    size = torch.tensor([0.7, 2.4])
    prior = fit(sizes, labels, 3, weight=0.3)
    like = prior.log_likelihood(size).exp()
    expect = probs.double() * like ** 0.3
    np.testing.assert_allclose(prior.apply(probs, size).numpy(), (expect / expect.sum(1, keepdim=True)).numpy(),
                               rtol=1e-6)
    # a small object is pulled toward the small class, a large one toward the large class
    out = fit(sizes, labels, 3, weight=1.0).apply(torch.full((2, 3), 1 / 3), size)
    assert out[0].argmax() == 0 and out[1].argmax() == 2
    assert torch.equal(fit(sizes, labels, 3, weight=0.0).apply(probs, size), probs)
    for bad in ([0.0, 1.0], [float("nan"), 1.0], [-1.0, 1.0]):
        with pytest.raises(InputError, match="positive number of metres"):
            prior.apply(probs, torch.tensor(bad))


@pytest.mark.parametrize("change, reason", [
    ({"weight": float("nan")}, "finite numbers"),
    ({"log_scale": [0.1, -0.2, 0.1]}, "log_scale must be positive"),
    ({"log_median": [0.0, 1.0]}, "3 finite numbers"),
    ({"log_median": ["a", 1.0, 2.0]}, "3 finite numbers"),
    ({"outlier": 1.5}, "outlier in"),
    ({"extra": 1}, "expected the keys"),
])
def test_a_hostile_prior_in_a_checkpoint_is_refused_by_name(tmp_path, change, reason):
    model = RecurrentAttention(ModelConfig(num_classes=3))
    good = fit(*sample(), 3).to_dict()
    path = tmp_path / "m.pt"
    payload = {"model": model.state_dict(), "model_args": model.config.to_dict(), "classes": list("abc")}
    checkpoint.save(path, {**payload, "size_prior": good})
    loaded = checkpoint.load_model(path)[0].size_prior
    assert loaded == SizePrior.from_dict(good, 3) and loaded.to_dict() == good  # round trip
    checkpoint.save(path, {**payload, "size_prior": {**good, **change}})
    with pytest.raises(checkpoint.CheckpointError, match=reason):
        checkpoint.load_model(path)
    checkpoint.save(path, payload)
    assert checkpoint.load_model(path)[0].size_prior is None


def test_an_episode_answers_its_readout_weighed_by_the_prior_and_keeps_the_plain_mean():
    torch.manual_seed(0)
    model = RecurrentAttention(ModelConfig(num_classes=3, readout="mean", view_input=True)).eval()
    depth = torch.rand(4, 2, 64, 64) * 255
    views = torch.rand(4, 2, 2)
    size = torch.tensor([0.6, 2.5])
    plain, weighed = Episode(model, EpisodeConfig(4)), Episode(model, EpisodeConfig(4))
    model.size_prior = fit(*sample(), 3, weight=0.8)
    with torch.no_grad():
        plain.reset(views[0])
        weighed.reset(views[0], size)
        for t in range(4):
            plain.move_to(views[t])
            weighed.move_to(views[t])
            saved, model.size_prior = model.size_prior, None
            plain.step(depth[t])  # the same model, without its prior
            model.size_prior = saved
            weighed.step(depth[t])
            expect = model.size_prior.apply(plain.probs[-1], size)
            torch.testing.assert_close(weighed.probs[-1], expect)  # the mean stays the images'


def test_modelnet_sizes_come_from_the_files_in_inches_through_the_cache(tmp_path):
    for c, scale in (("chair", 30.0), ("table", 50.0)):
        for split in ("train", "test"):
            d = tmp_path / c / split
            d.mkdir(parents=True)
            for i in range(2):
                box = np.array(CUBE_V) * [scale * (i + 1), 0.5 * scale, 0.25 * scale]
                write_off(d / f"{c}_{i}.off", box, CUBE_QUADS)
    cold = open_dataset("modelnet", tmp_path, "train", cache_dir=tmp_path / "cache")
    warm = open_dataset("modelnet", tmp_path, "train", cache_dir=tmp_path / "cache")
    assert warm.loaded["cache"] == 4 and warm.loaded.get("converted", 0) == 0
    expect = [30 * INCH, 60 * INCH, 50 * INCH, 100 * INCH]
    for ds in (cold, warm):
        assert [ds.size(i) for i in range(4)] == pytest.approx(expect)
    shapes = Shapes(warm, CameraConfig(16, 16))
    np.testing.assert_allclose(shapes.sizes([3, 0]), [100 * INCH, 30 * INCH])
    # turned by 45 degrees, a box 1 x 0.5 (longest edge 1) spans (1 + 0.5) / sqrt(2) in x and y
    turned = Shapes(warm, CameraConfig(16, 16), yaw=45.0)
    turned.yaws[:] = math.radians(45)
    np.testing.assert_allclose(turned.sizes([0]), [30 * INCH * 1.5 / math.sqrt(2)], rtol=1e-5)
    # a generated dataset has no sizes (10 shapes a class: one each in val, not all 2,000 built)
    procedural_val = open_dataset("procedural", split="val", per_class=10)
    assert Shapes(procedural_val, CameraConfig(16, 16)).sizes([0, 1]) is None


def test_a_checkpoint_entry_is_fitted_on_the_training_sizes_or_left_out_with_a_warning():
    class Fake:
        def __init__(self, sizes, labels):
            self._sizes, self.labels = np.asarray(sizes), np.asarray(labels)

        def __len__(self):
            return len(self.labels)

        def sizes(self, idx):
            return None if self._sizes is None else self._sizes[list(idx)]

    sizes, labels = sample()
    entry = size_prior.entry(Fake(sizes, labels), 3)["size_prior"]
    assert entry == fit(sizes, labels, 3).to_dict()
    assert size_prior.entry(type("Unknown", (Fake,), {"sizes": lambda self, idx: None})(sizes, labels), 3) == {}
    with pytest.warns(UserWarning, match="class 2 has 1"):
        assert size_prior.entry(Fake([1.0, 1.1, 2.0, 2.2, 3.0], [0, 0, 1, 1, 2]), 3) == {}


@pytest.mark.parametrize("use_size", [True, False])
def test_the_recognizer_tells_the_episode_its_object_size_unless_told_not_to(use_size):
    core = ActiveRecognizer(checkpoint.shipped("modelnet"),
                            sensing=SensingConfig(object_size=0.7, use_size=use_size))
    assert core.model.size_prior is not None  # modelnet10.pt carries one
    if use_size:
        assert core.episode.size.tolist() == pytest.approx([0.7])
    else:
        assert core.episode.size is None
    core.reset(sensing=SensingConfig(object_size=1.9, use_size=use_size))
    assert (core.episode.size is None) != use_size


def test_training_on_modelnet_writes_the_prior_of_its_training_split_less_validation(tmp_path):
    from active_recognition.datasets import open_splits
    from active_recognition.training.train import TrainConfig, train
    for c, inches in (("large", 40.0), ("small", 10.0)):
        for split, n in (("train", 8), ("test", 1)):
            (tmp_path / c / split).mkdir(parents=True)
            for i in range(n):
                box = np.array(CUBE_V) * [inches * (1 + 0.05 * i), 0.6 * inches, 0.4 * inches]
                write_off(tmp_path / c / split / f"{c}_{i}.off", box, CUBE_QUADS)
    train(TrainConfig(dataset="modelnet", root=str(tmp_path), out=str(tmp_path / "run"), pretrain_epochs=1,
                      joint_epochs=1, batch_size=4, steps=2, views_per_shape=2, eval_shapes=0, seed=1,
                      model={"hidden_size": 8, "feature_size": 8}), progress=False)
    prior = checkpoint.load_model(tmp_path / "run" / "final.pt")[0].size_prior
    ds = open_splits("modelnet", tmp_path, ("train",), None)["train"]
    assert len(ds) < 16  # the validation objects are not in it
    expect = fit([ds.size(i) for i in range(len(ds))], ds.labels(), 2)
    assert prior == expect
    assert np.exp(prior.log_median) == pytest.approx([40 * INCH * 1.175, 10 * INCH * 1.175], rel=0.06)
