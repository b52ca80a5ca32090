# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""Episodes through a simulated camera, as the node runs them (camera_episodes.py), and the
`unknown` answer fitted on them (open_set_fit --camera)."""
import numpy as np
import pytest
import torch

from active_recognition.datasets import open_dataset
from active_recognition.evaluation.camera_episodes import CameraRun, camera_runs, full_length, shown_size
from active_recognition.model import checkpoint
from active_recognition.model.episode import EpisodeConfig
from active_recognition.runtime.active_recognizer import ActiveRecognizer, SensingConfig
from active_recognition.unknown import fit as open_set_fit, scores as open_set


@pytest.fixture()
def procedural_test(dataset_cache, monkeypatch):
    monkeypatch.setenv("ACTIVE_RECOGNITION_CACHE", str(dataset_cache))
    return open_dataset("procedural", None, "test", cache_dir=dataset_cache)


def test_recorded_runs_hold_each_images_answer_and_state(procedural_test):
    """Without a stop every run takes max_views images; each recorded answer is a distribution,
    the last one is the run's answer (right where it names the object's class), one state is
    kept per image, and the last is the state the episode ended with."""
    path = checkpoint.shipped("procedural")
    core = ActiveRecognizer(path, EpisodeConfig(3, 0.0), sensing=SensingConfig(use_size=False))
    objects = [0, 7, 40]
    runs = camera_runs(core, procedural_test, "procedural", "test", objects, "virtual", seed=1, record=True)
    probs, states, whole = full_length(runs, 3)
    assert len(whole) == 3 and probs.shape[:2] == (3, 3) and states.shape == (3, 3, core.model.config.state_size)
    np.testing.assert_allclose(probs.sum(-1), 1.0, atol=1e-5)
    for i, r, p in zip(objects, runs, probs):
        assert r.status == "unsure" and r.label == procedural_test.items[i][1]  # never sure: threshold 0
        assert r.right == (int(p[-1].argmax()) == r.label)
    # the last state is the one the episode ended with
    np.testing.assert_allclose(states[-1, -1], core.episode.hidden[0].numpy(), rtol=1e-6)
    assert not np.allclose(states[0, 0], states[0, 1])  # one per image, not one copied


def test_a_sensor_config_stands_for_its_preset_and_its_changes_reach_the_images(procedural_test):
    """camera_runs takes a SensorConfig as well as a preset's name (camera_parts' rows of the
    camera's defects): the preset's own config gives the same images, hence the same answers, and
    a camera that loses half its pixels gives other ones."""
    from active_recognition.simulation.depth_sensor import sensor_config

    path = checkpoint.shipped("procedural")
    core = ActiveRecognizer(path, EpisodeConfig(2, 0.0), sensing=SensingConfig(use_size=False))

    def answers(camera):
        runs = camera_runs(core, procedural_test, "procedural", "test", [2, 9], camera, seed=3, record=True)
        return np.stack([np.stack(r.probs) for r in runs])

    named = answers("virtual")
    np.testing.assert_array_equal(answers(sensor_config("virtual")), named)
    assert not np.allclose(answers(sensor_config("virtual", dropout=0.5)), named)


def test_a_run_without_images_is_left_out_of_full_length(procedural_test):
    path = checkpoint.shipped("procedural")
    core = ActiveRecognizer(path, EpisodeConfig(2, 0.0), sensing=SensingConfig(use_size=False))
    runs = camera_runs(core, procedural_test, "procedural", "test", [3], "virtual", seed=0, record=True)
    runs[0].probs, runs[0].states = runs[0].probs[:1], runs[0].states[:1]  # as if one image came
    with pytest.raises(ValueError):  # nothing left to stack
        full_length(runs, 2)


def test_sizes_shown_are_kept_within_the_datasets_bounds():
    class Sized:
        def __init__(self, size):
            self.value = size

        def size(self, i):
            return self.value

    assert shown_size(Sized(115.0), 0) == 3.0 and shown_size(Sized(0.1), 0) == 0.3
    assert shown_size(Sized(0.5), 0) == 0.5 and shown_size(Sized(None), 0) == 1.0


def test_the_answer_fitted_through_a_camera_keeps_the_better_means_on_val(dataset_cache, monkeypatch):
    """open_set_fit --camera: one threshold per step from episodes through the camera, the
    means whose val AUROC is the higher (the renders' exactly where those were chosen), and a
    val rejection within the asked share."""
    monkeypatch.setenv("ACTIVE_RECOGNITION_CACHE", str(dataset_cache))
    path = checkpoint.shipped("procedural")
    entry = open_set_fit.fit(path, "procedural", objects=20, known_rate=0.8, steps=3, val_objects=10,
                             camera="virtual")
    fitted = entry["fitted_on"]
    by = fitted["val_auroc_by_means"]
    assert fitted["camera"] == "virtual" and fitted["means_from"] == max(by, key=by.get)
    assert fitted["val_auroc"] == pytest.approx(by[fitted["means_from"]], abs=1e-4)
    assert len(entry["threshold"]) == 3 and fitted["val_known_rejected"] <= 0.2
    rendered = open_set_fit.fit(path, "procedural", objects=20, known_rate=0.8, steps=3, val_objects=10)
    assert rendered["fitted_on"]["camera"] == "model"
    assert torch.equal(entry["means"], rendered["means"]) == (fitted["means_from"] == "renders")
    assert open_set.step_thresholds(entry["threshold"], 3).shape == (3,)


def test_each_runs_evidence_is_recorded_image_by_image(dataset_cache, monkeypatch, tmp_path):
    """A run keeps each classified image's energy and prototype score: as many as its images,
    the prototypes those of its recorded states against the checkpoint's means (recomputed
    here), their mean the run's score, and no prototype where the checkpoint has no means."""
    monkeypatch.setenv("ACTIVE_RECOGNITION_CACHE", str(dataset_cache))
    path = checkpoint.shipped("procedural")
    fitted = tmp_path / "open_set.pt"
    open_set_fit.store(path, open_set_fit.fit(path, "procedural", objects=20, steps=3, val_objects=5), fitted)
    test = open_dataset("procedural", None, "test", cache_dir=dataset_cache)
    sensing = SensingConfig(use_size=False, unknown_threshold=0.0, hold_unknown=False)
    core = ActiveRecognizer(str(fitted), EpisodeConfig(3, 0.0), sensing=sensing)
    runs = camera_runs(core, test, "procedural", "test", [0, 5], "virtual", seed=2, record=True)
    means = core.model.open_set["means"].numpy()
    for r in runs:
        assert len(r.energies) == len(r.prototypes) == len(r.probs) == 3 and np.isfinite(r.energies).all()
        again = open_set.prototype_steps(np.stack(r.states)[None], means)[0]
        np.testing.assert_allclose(r.prototypes, again, rtol=1e-5, atol=1e-6)
        assert r.score == pytest.approx(np.mean(r.prototypes))
    plain = ActiveRecognizer(path, EpisodeConfig(2, 0.0), sensing=SensingConfig(use_size=False))
    run = camera_runs(plain, test, "procedural", "test", [0], "virtual", seed=2)[0]
    assert len(run.energies) == 2 and run.prototypes == [] and np.isnan(run.score)


def test_validation_through_the_camera_scores_answers_by_views_and_keeps_a_default_within_its_error():
    """benchmarks/validation_camera.py: an answer after t views is the last image's by then (none
    before the first); the rule moves off the default only for a lead above one paired s.e."""
    from conftest import load_benchmark

    vc = load_benchmark("validation_camera")
    one_hot = lambda c: np.eye(3)[c]  # noqa: E731
    runs = [CameraRun("recognized", 1, True, 0.1, [one_hot(0), one_hot(1)], [], [-1.0, -2.0], [0.2, 0.4]),
            CameraRun("no_object", 2, False, float("nan"), [], [], [], [])]
    np.testing.assert_array_equal(vc.answers(runs, 4), [[0, 1, 1, 1], [-1, -1, -1, -1]])
    ends = vc.end_scores(runs, 1)
    assert ends["prototype_mean"][0] == pytest.approx(0.2) and ends["energy_mean"][0] == -1.0
    assert ends["msp_mean"][0] == 0.0 and np.isinf(ends["prototype_mean"][1])
    assert vc.end_scores(runs, 2)["prototype_mean"][0] == pytest.approx(0.3)
    base = np.zeros((40, 3))

    def rows(right, auroc):
        return {p: {"mean": float(r.mean()), "auroc": {"prototype_mean": [0.5, a]}}
                for (p, r), a in zip(right.items(), auroc)}

    close = {"learned": base.copy(), "imitation": base.copy()}
    close["imitation"][:2], close["learned"][2] = 1, 1  # 2 better, 1 worse of 40: 0.025 against s.e. 0.044
    assert vc.paired(close, "imitation", "learned") == pytest.approx((0.025, 0.0437), abs=1e-4)
    assert vc.rule(rows(close, (0.97, 0.98)), close) == ("imitation", ["learned", "imitation"])
    assert vc.rule(rows(close, (0.99, 0.98)), close)[0] == "learned"  # a tie goes to the better AUROC
    clear = {"learned": base.copy(), "imitation": base.copy()}
    clear["learned"][:8] = 1  # 8 of 40: 0.2 against s.e. 0.064
    assert vc.rule(rows(clear, (0.97, 0.99)), clear) == ("learned", ["learned"])  # accuracy first
    # a checkpoint without class means: no prototype score; energy_mean breaks the tie
    plain = [CameraRun("recognized", 0, True, 0.1, [one_hot(0)], [], [-1.0], []) for _ in range(3)]
    odd = [CameraRun("recognized", 1, False, 0.1, [one_hot(1)], [], [e], []) for e in (-3.0, 0.5)]
    _, row = vc.summarise({"known": [plain], "unknown": odd})
    assert "prototype_mean" not in row["auroc"] and row["auroc"]["energy_mean"][0] == pytest.approx(0.5)
    energy = {p: {"mean": float(r.mean()), "auroc": {"energy_mean": [0.5, a]}}
              for (p, r), a in zip(close.items(), (0.9, 0.8))}
    assert vc.rule(energy, close)[0] == "learned"
    both = {p: {"mean": float(r.mean()), "auroc": {"prototype_mean": [0.5, a], "energy_mean": [0.5, b]}}
            for (p, r), a, b in zip(close.items(), (0.9, 0.8), (0.8, 0.9))}
    assert vc.rule(both, close)[0] == "learned" and vc.rule(both, close, "energy_mean")[0] == "imitation"
    # --scores: a row an episode, per view its answer and scores, blank past its views
    table = vc.score_rows({"known": [runs], "unknown": odd}, near=np.array([True, False]))
    head = table[0]
    assert head[:4] == ["group", "object", "label", "near"] and len(head) == 4 + 4 * vc.STEPS
    first = dict(zip(head, table[1]))
    assert (first["answer_1"], first["answer_2"], first["answer_3"]) == ("0", "1", "1")
    assert first["prototype_2"] == "0.4" and first["energy_1"] == "-1" and first["msp_1"] == "0"
    assert first["prototype_3"] == "" and dict(zip(head, table[3]))["answer_1"] == "1"
    assert [r[0] for r in table[1:]] == ["known", "known", "unknown", "unknown"] and table[3][3] == 1


def test_shipping_the_validation_choice_records_it_for_the_nodes_auto(tmp_path):
    """validation_camera --ship: the checkpoint's planner `auto` and the test summary's default
    become the chosen planner; the rest of both is kept and the model still loads."""
    import json
    import shutil

    from conftest import load_benchmark

    from active_recognition.runtime.active_recognizer import choose_planner

    vc = load_benchmark("validation_camera")
    path, summary = tmp_path / "m.pt", tmp_path / "summary.json"
    shutil.copy(checkpoint.shipped("procedural"), path)
    summary.write_text(json.dumps({"acc": {"random": {"3": 0.5}}, "default_planner": "imitation"}))
    before = checkpoint.read(path)
    vc.ship(path, "random", summary)
    model, _, after = checkpoint.load_model(path)
    assert choose_planner("auto", model, after) == "random" and before["default_planner"] != "random"
    assert after.get("fixed_path") == before.get("fixed_path") and after["config"] == before["config"]
    assert json.loads(summary.read_text()) == {"acc": {"random": {"3": 0.5}}, "default_planner": "random",
                                               "default_chosen_by": "validation_camera.json"}


def test_a_camera_run_cut_short_answers_as_a_robot_allowed_that_many_images_would():
    """open_set_camera's cut: after t images the answer then, `unknown` where the running
    prototype score (or energy, for energy_mean) is above that step's threshold; a run that ended
    sooner as it ended."""
    from conftest import load_benchmark

    osc = load_benchmark("open_set_camera")
    one_hot = lambda c: np.eye(3)[c]  # noqa: E731
    run = CameraRun("recognized", 2, True, 0.3, [one_hot(0), one_hot(2), one_hot(2)], [], [-1.0] * 3,
                    [0.9, 0.1, 0.1])
    assert osc.cut(run, 1, [0.5, 0.6]) == (True, False)  # 0.9 above 0.5: unknown after one image
    assert osc.cut(run, 2, [0.5, 0.6]) == (False, True)  # mean 0.5 within 0.6, class 2 right
    assert osc.cut(run, 2, [0.5, 0.4]) == (True, False)  # mean 0.5 above 0.4
    assert osc.cut(run, 3, [0.5, 0.6]) == (False, True)  # as it ended
    ended = CameraRun("unknown", 2, False, 0.8, [one_hot(2)], [], [-1.0], [0.8])
    assert osc.cut(ended, 3, [0.5]) == (True, False)
    assert osc.cut(CameraRun("no_object", 1, False, float("nan"), [], [], [], []), 3, [0.5]) == (False, False)
    energetic = CameraRun("recognized", 2, True, -2.0, [one_hot(0), one_hot(2), one_hot(2)], [], [-1.0, -3.0, -3.0],
                          [0.9, 0.1, 0.1])  # energy_mean: the energies decide, the prototypes do not
    assert osc.cut(energetic, 1, [-1.5, -2.5], "energy_mean") == (True, False)  # -1.0 above -1.5
    assert osc.cut(energetic, 2, [-1.5, -1.5], "energy_mean") == (False, True)  # mean -2.0 within -1.5
    assert osc.cut(energetic, 2, [-1.5, -2.5], "energy_mean") == (True, False)  # mean -2.0 above -2.5


def test_camera_parts_rows_take_each_defect_of_the_camera_away_alone():
    """--sensor-parts adds one row per defect of the RealSense preset: each row's changes are
    SensorConfig fields, each undoes something the preset has (the row differs from the preset
    in exactly the fields it names), and the rows run today's model with the node's own sensing."""
    from dataclasses import asdict
    from types import SimpleNamespace

    from conftest import load_benchmark

    from active_recognition.simulation.depth_sensor import sensor_config

    parts = load_benchmark("camera_parts")
    args = SimpleNamespace(checkpoint=None, other_checkpoint=None, planners=[], sensor_parts=True)
    preset = asdict(sensor_config("realsense"))
    rows = [r for r in parts.rows(args) if r[4]]
    assert [r[0] for r in rows] == list(parts.SENSOR_PARTS)
    for name, _, planner, changes, sensor in rows:
        changed = asdict(sensor_config("realsense", **sensor))
        assert {k for k in preset if preset[k] != changed[k]} == set(sensor), name
        assert planner == "auto" and changes == {}
    args.sensor_parts = False
    assert not [r for r in parts.rows(args) if r[4]]
