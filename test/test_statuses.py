# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""Statuses that say what happened, without rclpy: an answer below the node's confidence
(LabelInfo's threshold) ends unsure with its best guess, whether max_views or the time budget
stopped it; images refused for want of their transform turn /diagnostics WARN then ERROR, naming
TF and its frames, not the camera."""
import numpy as np
import pytest

from active_recognition.checkpoint import shipped
from active_recognition.controller import Controller, End, Timing
from active_recognition.episode import EpisodeConfig, least_top_score
from active_recognition.recognizer import ActiveRecognizer
from active_recognition.simulated_camera import SimulatedCamera


@pytest.fixture(scope="module")
def camera():
    sim = SimulatedCamera(seed=0)
    sim.load(dataset="procedural", split="test", index=3)
    return sim


def episode(core, camera, confidence=None):
    """The last Observation of one seeded episode, under the core's confidence or the one given."""
    core.rng = np.random.default_rng(0)
    core.reset()
    if confidence is not None:
        core.confidence = confidence
    while not core.done:
        obs = core.observe(*camera.capture(*core.requested_pose())[:1])
    return obs


def test_an_answer_stopped_by_max_views_below_the_confidence_ends_unsure_with_its_best_guess(camera):
    core = ActiveRecognizer(str(shipped("procedural")), EpisodeConfig(max_views=2, entropy_threshold=0.1))
    assert core.confidence == least_top_score(0.1, len(core.classes))  # LabelInfo's threshold, one source
    obs = episode(core, camera)
    top = float(obs.probs.max())
    assert obs.views == 2 and top < core.confidence  # stopped by max_views, not by its entropy
    result = obs.result()
    assert result["status"] == "unsure" and result["label"] == core.classes[int(obs.probs.argmax())]
    assert result["probability"] == pytest.approx(top) and result["entropy"] == pytest.approx(obs.entropy)
    # the same episode with the confidence at its top probability: recognized; just above it: unsure
    assert episode(core, camera, top).status == "recognized"
    assert episode(core, camera, top + 1e-4).status == "unsure"


def test_an_answer_stopped_by_the_time_budget_below_the_confidence_ends_unsure(camera):
    core = ActiveRecognizer(str(shipped("procedural")), EpisodeConfig(entropy_threshold=0.0))  # confidence 1
    core.rng = np.random.default_rng(0)
    loop = Controller(core, Timing(pose_wait=0.05, budget_entropy_threshold=0.0))
    commands, now = loop.start(0.0, time_budget=2.0), 0.0
    while not any(isinstance(c, End) for c in commands):
        ask = [c for c in commands if type(c).__name__ == "AskView"][-1]
        now += 0.1
        metres, position, rotation = camera.capture(ask.position, ask.rotation)
        commands = loop.pose(now, ask.frame, ask.stamp, position, rotation) + loop.image(now, ask.stamp, metres)
    end = commands[-1]
    assert 1 <= end.result["views"] < core.episode.config.max_views  # the budget stopped it
    assert end.result["status"] == "unsure" and end.result["label"] and 0 < end.result["probability"] < 1
    assert loop.report(now)[2]["episodes unsure"] == 1  # /diagnostics counts it by its status
