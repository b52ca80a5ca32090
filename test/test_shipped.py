# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""The shipped checkpoint: loads from the package alone and scores what the README says."""
import functools
import math
import re
from pathlib import Path

import numpy as np
import pytest
import torch

from active_recognition.datasets import default_cache_dir, open_dataset
from active_recognition.datasets.shapes import Shapes
from active_recognition.model import checkpoint
from active_recognition.model.episode import Episode, EpisodeConfig, run
from active_recognition.model.policies import make_planner
from active_recognition.sensing.depth_layer import CameraConfig
from active_recognition.sensing.reach import ViewLimits, reach_of

README = Path(__file__).resolve().parents[1] / "README.md"


@functools.lru_cache
def trained_limits(dataset="procedural"):
    """The views the dataset's shipped model was trained on (its run's elevation limits)."""
    config = checkpoint.read(checkpoint.shipped(dataset)).get("config", {})
    return ViewLimits(config.get("min_elevation", -90.0), config.get("max_elevation", 90.0))


def episodes(n, seed, dataset="procedural"):
    """n seeded test objects and initial views (among the paper's 50, inside the views the
    model was trained on), seen through the dataset's shipped model's camera."""
    config = checkpoint.load_model(checkpoint.shipped(dataset))[0].config
    test = Shapes(open_dataset(dataset, split="test", cache_dir=default_cache_dir()),
                  CameraConfig(config.image_size, config.image_size, radius=config.radius))
    rng = np.random.default_rng(seed)
    idx = np.sort(rng.permutation(len(test))[:n])
    starts = trained_limits(dataset).initial_views(50)
    return test, idx, starts[rng.integers(0, len(starts), n)]


def final_probs(model, test, idx, views, steps, planner=None, dataset="procedural"):
    """Class probabilities after `steps` views, every view kept inside the trained limits."""
    reach = reach_of(trained_limits(dataset))
    with torch.no_grad():
        out = run(Episode(model, EpisodeConfig(steps), planner, reach=reach), test.cameras(idx),
                  views, steps)
    return out[-1].probs


def accuracy(model, test, idx, views, steps, planner=None, dataset="procedural"):
    probs = final_probs(model, test, idx, views, steps, planner, dataset)
    return (probs.argmax(1) == torch.as_tensor(test.labels[idx])).float().mean().item()


def readme(marker):
    return float(re.search(rf"<!-- {marker} -->\s*([0-9.]+)", README.read_text()).group(1))


def check_readme_accuracy(marker, probs, labels):
    """The README's figure after `marker` is this sample's own accuracy, to its two decimals.

    The tolerance is the README's rounding, 0.005, and no more: the figure is not an estimate of
    this sample's accuracy but the accuracy itself, so a gap of one object (1 / n) would be a
    stale README, not noise. The sample's standard error, sqrt(p (1 - p) / n), is what the figure
    is worth as the model's accuracy: two decimals are enough when it exceeds the rounding (it
    is 0 only at p = 0 or 1, where rounding loses nothing). Floating-point differences between
    machines could flip only an object whose two best classes nearly tie; the nearest tie is
    printed and must be far above float noise."""
    n = len(labels)
    acc = (probs.argmax(1) == torch.as_tensor(labels)).float().mean().item()
    se = math.sqrt(acc * (1 - acc) / n)
    top2 = probs.topk(2, 1).values
    tie = (top2[:, 0] - top2[:, 1]).min().item()
    print(f"{marker}: accuracy {acc:.3f} on {n} objects, standard error {se:.3f}, nearest tie "
          f"{tie:.3f}; README {readme(marker)}")
    assert se > 0.005 or acc in (0.0, 1.0)
    assert tie > 1e-3
    assert abs(acc - readme(marker)) <= 0.005 + 1e-9


def test_no_model_file_means_the_shipped_model_of_the_objects_dataset():
    assert checkpoint.model_path(None) == checkpoint.model_path("") == checkpoint.shipped("procedural")
    assert checkpoint.model_path("", "modelnet").name == "modelnet10.pt"  # the node's real objects
    assert checkpoint.model_path("runs/x/final.pt", "modelnet") == Path("runs/x/final.pt")
    assert all((checkpoint.MODELS / f).is_file() for f in checkpoint.SHIPPED_FOR.values())
    with pytest.raises(checkpoint.InputError, match="none is shipped for the folder dataset"):
        checkpoint.load_model(None, dataset="folder")


def test_shipped_checkpoint_matches_the_readme_figure():
    """procedural.pt with the planner 'auto' stands for (the checkpoint's default_planner, and
    its fixed path) scores the README's figure after 3 views on 100 seeded test objects."""
    model, classes, ckpt = checkpoint.load_model()  # the package's own file, nothing else
    assert classes[0] == "bathtub" and len(classes) == 10 and ckpt["config"]["dataset"] == "procedural"
    test, idx, views = episodes(100, seed=2024)
    planner = make_planner(ckpt["default_planner"], model=model, fixed_path=ckpt.get("fixed_path"))
    check_readme_accuracy("shipped-acc3", final_probs(model, test, idx, views, 3, planner),
                          test.labels[idx])


@pytest.mark.parametrize("dataset,marker", [("procedural", "shipped-minutes"),
                                            ("twins", "twins-minutes"),
                                            ("modelnet", "modelnet10-minutes")])
def test_the_readme_training_time_is_the_one_the_checkpoint_recorded(dataset, marker):
    """The README's minutes are the shipped run's own clock (the checkpoint's `elapsed`)."""
    elapsed = checkpoint.read(checkpoint.shipped(dataset))["elapsed"]
    print(f"{dataset}.pt trained for {elapsed / 60:.1f} minutes; README {readme(marker)}")
    assert round(elapsed / 60) == readme(marker)


def test_oracle_is_not_worse_than_random_with_the_shipped_model():
    model, _, _ = checkpoint.load_model()
    test, idx, views = episodes(30, seed=5)
    cams = test.cameras(idx)
    accs = {}
    for name in ("random", "oracle"):
        planner = make_planner(name, cams, seed=5, candidates=20, labels=test.labels[idx])
        accs[name] = accuracy(model, test, idx, views, 2, planner)
    assert accs["oracle"] >= accs["random"], accs


def test_greedy_picks_the_least_entropy_candidate_by_brute_force():
    model, _, _ = checkpoint.load_model()
    test, idx, views = episodes(3, seed=9)
    cams = test.cameras(idx)
    oracle = make_planner("greedy", cams, candidates=12)
    ep = Episode(model, EpisodeConfig(4), oracle)
    with torch.no_grad():
        run(ep, cams, views, 2)  # two steps: the cached features are reused at the second
        for i, cam in enumerate(cams):
            depth = torch.from_numpy(cam.render(oracle.candidates))
            logits, _, _ = model(depth, ep.hidden[i:i + 1].expand(len(depth), -1).clone(),
                                 torch.as_tensor(oracle.candidates, dtype=torch.float32))
            p = logits.softmax(-1)
            h = -(p * p.clamp_min(1e-12).log()).sum(-1)
            # the oracle's choice after step 2, recomputed the slow way from the same state
            chosen = oracle.next_view(ep, None)[i]
            np.testing.assert_allclose(chosen, oracle.candidates[int(h.argmin())])


def test_the_oracle_picks_the_unvisited_candidate_right_by_the_widest_margin_by_brute_force():
    """The oracle's next view is the unvisited candidate after which the episode's answer (the
    shipped model's readout: its last step's, or the mean of every step's) puts the true class
    furthest above the strongest other."""
    from active_recognition.model.policies import nearest_candidates

    model, _, _ = checkpoint.load_model()
    test, idx, views = episodes(3, seed=9)
    cams, labels = test.cameras(idx), test.labels[idx]
    oracle = make_planner("oracle", cams, candidates=12, labels=labels)
    ep = Episode(model, EpisodeConfig(4), oracle)
    with torch.no_grad():
        run(ep, cams, views, 3)
        taken = [nearest_candidates(v.numpy(), oracle.candidates) for v in ep.views]  # + the next
        chosen = oracle.next_view(ep, None)
        for i, cam in enumerate(cams):
            depth = torch.from_numpy(cam.render(oracle.candidates))
            logits, _, _ = model(depth, ep.hidden[i:i + 1].expand(len(depth), -1).clone(),
                                 torch.as_tensor(oracle.candidates, dtype=torch.float32))
            p = logits.softmax(-1)
            if model.config.readout != "last":
                p = (ep.probs[-1][i] * ep.steps + p) / (ep.steps + 1)  # no size prior: the mean
            p = p.numpy()
            margin = p[:, labels[i]] - np.delete(p, labels[i], 1).max(1)
            margin[[t[i] for t in taken]] = -math.inf  # never a view it has taken
            np.testing.assert_allclose(chosen[i], oracle.candidates[int(margin.argmax())])


def test_shipped_twins_model_chooses_views_that_pay():
    """twins.pt with its own planner (FC_view) scores the README's figure after 3 views on 120
    seeded test objects (see check_readme_accuracy) and beats random views by 8 points on the
    same episodes."""
    model, classes, ckpt = checkpoint.load_model(checkpoint.shipped("twins"))
    assert ckpt["config"]["dataset"] == "twins" and len(classes) == 12
    assert ckpt["default_planner"] == "imitation" and model.config.view_input
    test, idx, views = episodes(120, seed=2024, dataset="twins")
    own = final_probs(model, test, idx, views, 3, make_planner("imitation", model=model), "twins")
    check_readme_accuracy("twins-acc3", own, test.labels[idx])
    rand = accuracy(model, test, idx, views, 3, make_planner("random", seed=1), "twins")
    own = (own.argmax(1) == torch.as_tensor(test.labels[idx])).float().mean().item()
    print(f"twins.pt after 3 views: imitation {own:.3f}, random {rand:.3f}")
    assert own >= rand + 0.08
