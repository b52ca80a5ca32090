# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""Without ROS: the recognizer's health bookkeeping and level, the LabelInfo threshold, the
camera inside the object's box, and an episode that runs past its time."""
import math

import numpy as np
import pytest

from active_recognition.argument_checks import InputError
from active_recognition.runtime.active_recognizer import ActiveRecognizer, least_top_score
from active_recognition.runtime.health import Health, MIN_FRAMES, WINDOW_S, unconfigured
from active_recognition.sensing import camera_input_bounds
from active_recognition.sensing.reach import ViewLimits
from active_recognition.simulation.depth_sensor import SimulatedCamera


def test_a_silent_camera_during_an_episode_warns_and_a_frame_clears_it():
    health = Health()
    assert health.level(0.0, view_timeout=3.0) == ("OK", "waiting for ~/reset")
    assert health.level(100.0, 3.0)[0] == "OK"  # no episode: silence is expected
    health.started(100.0)
    assert health.level(102.9, 3.0)[0] == "OK"
    level, message = health.level(103.5, 3.0)
    assert level == "WARN" and "no image for 3.5 s" in message
    health.frame(103.6)
    assert health.level(104.0, 3.0) == ("OK", "recognizing")
    assert health.level(106.7, 3.0)[0] == "WARN"  # silent again
    assert health.level(106.7, 3.0, active=False) == ("OK", "inactive: images are ignored")
    assert health.level(106.7, 3.0, active=False, state="unconfigured")[1] == "unconfigured: images are ignored"
    health.resumed(10.0)  # inactive for 10 s: that silence is not the camera's
    assert health.level(116.0, 3.0)[0] == "OK"
    health.ended("recognized")
    assert health.level(200.0, 3.0)[0] == "OK" and health.values(200.0)["episodes recognized"] == 1


@pytest.mark.parametrize("frames,refused,level", [(10, 6, "WARN"), (10, 5, "OK"),
                                                  (MIN_FRAMES - 1, MIN_FRAMES - 1, "OK")])
def test_more_than_half_the_frames_of_the_window_refused_warns(frames, refused, level):
    health = Health()
    for i in range(frames):
        health.frame(i * 0.1)
        if i < refused:
            health.refuse(i * 0.1)
    got, message = health.level(1.0, 3.0)
    assert got == level, message
    if level == "WARN":
        assert f"{refused} of {frames} frames refused" in message
    assert health.level(1.0 + WINDOW_S + 0.1, 3.0)[0] == "OK"  # they leave the window


def test_rates_and_latency_are_over_the_window_and_an_unloaded_model_is_an_error():
    health = Health()
    rng = np.random.default_rng(0)
    ms = rng.uniform(5, 50, 300)
    for i, m in enumerate(ms):  # 30 Hz for 10 s
        health.frame(i / 30)
        health.step(i / 30, m)
    values = health.values(299 / 30)
    assert values["image rate (Hz)"] == pytest.approx(30.0, abs=0.2)
    assert values["step latency p50 (ms)"] == pytest.approx(np.percentile(ms, 50), rel=0.05)
    assert values["step latency p99 (ms)"] == pytest.approx(np.percentile(ms, 99), rel=0.05)
    later = health.values(299 / 30 + WINDOW_S + 1)
    assert later["image rate (Hz)"] == 0 and later["step latency p50 (ms)"] == "none"
    level, message, values = unconfigured(OSError("/x.pt: no such file"), "unconfigured")
    assert level == "ERROR" and "/x.pt: no such file" in message and values == {}
    assert unconfigured(None, "unconfigured")[:2] == ("OK", "unconfigured: images are ignored")


def entropy(p):
    p = p[p > 0]
    return float(-(p * np.log(p)).sum())


@pytest.mark.parametrize("threshold,n", [(0.1, 10), (0.5, 10), (1.0, 3), (0.05, 40)])
def test_the_label_info_threshold_is_the_least_top_score_below_the_entropy(threshold, n):
    score = least_top_score(threshold, n)
    rng = np.random.default_rng(1)
    for _ in range(2000):  # every distribution under the threshold has a top score above it
        p = rng.dirichlet(np.full(n, rng.choice([0.01, 0.05, 0.3])))
        if entropy(p) < threshold:
            assert p.max() >= score - 1e-9
    k = math.floor(1 / score)  # and the bound is met: the least-entropy distribution at it
    tight = np.array([score] * k + [1 - k * score] + [0.0] * (n - k - 1))
    assert entropy(tight) == pytest.approx(threshold, abs=1e-6)


def test_the_label_info_threshold_at_the_ends():
    assert least_top_score(0.0, 10) == 1.0  # never stops early: nothing below 0 nats
    assert least_top_score(math.log(10), 10) == pytest.approx(0.1)  # stops at once: anything
    assert least_top_score(0.1, 10) == pytest.approx(0.9794, abs=1e-3)


@pytest.mark.parametrize("position,centre", [((0.0, 0.0, 0.0), (0, 0, 0)), ((0.3, -0.4, 0.45), (0, 0, 0)),
                                             ((0.6, 0.0, 0.0), (0.2, 0.0, 0.0))])
def test_a_camera_inside_the_objects_box_is_refused_by_name(position, centre):
    with pytest.raises(InputError, match=r"camera/pose pose.position .* inside the object's box "
                                         r"\(edge 1 m, the parameter object_size"):
        camera_input_bounds.check_outside_box(position, centre, 1.0)


@pytest.mark.parametrize("position,centre,size", [((0.0, -1.5, 0.3), (0, 0, 0), 1.0),
                                                  ((0.6, 0.0, 0.0), (0, 0, 0), 1.0),
                                                  ((0.0, 0.0, 0.3), (0, 0, 0.0), 0.5),
                                                  ((0.3, 0.0, 0.0), (-0.25, 0.0, 0.0), 1.0)])
def test_a_camera_outside_the_box_passes(position, centre, size):
    np.testing.assert_array_equal(camera_input_bounds.check_outside_box(position, centre, size), position)


def test_an_episode_past_its_time_ends_with_timeout_and_the_best_guess_so_far():
    core = ActiveRecognizer(seed=1, limits=ViewLimits(0.0, 90.0))
    sim = SimulatedCamera()
    sim.load(dataset="procedural", split="test", index=0)
    assert core.time_out().result() == {"status": "timeout", "label": "", "probability": 0.0,
                                        "entropy": None, "views": 0}
    assert core.done
    with pytest.raises(RuntimeError, match="reset"):
        core.time_out()
    core.reset()
    assert not core.done
    obs = core.observe(sim.capture(*core.requested_pose(sim.k))[0], sim.k)
    end = core.time_out()
    assert end.status == "timeout" and end.done and core.done
    assert end.result() == {"status": "timeout", "label": obs.label,
                            "probability": pytest.approx(float(obs.probs.max())),
                            "entropy": pytest.approx(obs.entropy), "views": 1}
