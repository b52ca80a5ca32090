# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""Statuses that say what happened, without rclpy: an answer below the node's confidence
(LabelInfo's threshold) ends unsure with its best guess, whether max_views or the time budget
stopped it; images refused for want of their transform turn /diagnostics WARN then ERROR, naming
TF and its frames, not the camera."""
import numpy as np
import pytest

from active_recognition.model.checkpoint import shipped
from active_recognition.model.episode import EpisodeConfig, least_top_score
from active_recognition.runtime.active_recognizer import ActiveRecognizer
from active_recognition.runtime.controller import Controller, End, Timing
from active_recognition.runtime.controller_commands import Step
from active_recognition.simulation.depth_sensor import SimulatedCamera


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


def tf_loop(**timing):
    """A Controller whose poses come from TF alone (pose_source tf), as the node sets it."""
    core = ActiveRecognizer(str(shipped("procedural")))
    core.rng = np.random.default_rng(0)
    loop = Controller(core, Timing(pose_wait=0.2, view_timeout=1.0, **timing), pose_source="tf")
    loop.transform_missing("transform cam -> object (Lookup would require extrapolation)")
    return loop


def test_images_refused_for_want_of_a_transform_warn_then_error_naming_tf_until_one_is_classified(camera):
    loop = tf_loop(max_retries=5)
    ask, now, levels = loop.start(0.0)[0], 0.0, []
    metres, position, rotation = camera.capture(ask.position, ask.rotation)
    for _ in range(3):  # an image, and no transform for it
        loop.image(now, ask.stamp, metres)
        now += 0.25
        refused = [c for c in loop.tick(now) if type(c).__name__ == "Refuse"]
        assert refused and "no transform cam -> object (Lookup would require extrapolation)" in refused[0].reason
        levels.append(loop.report(now))
    assert [level for level, _, _ in levels] == ["WARN", "WARN", "ERROR"]
    assert all(m.startswith("TF: ") and "cam -> object" in m and "camera's images come" in m for _, m, _ in levels)
    resent = loop.tick(now + 1.0)  # view_timeout: its log names TF, not a silent camera
    assert "TF had no transform for them" in resent[0].reason and type(resent[1]).__name__ == "AskView"
    loop.pose(now + 1.1, "object", ask.stamp, position, rotation)  # a transform at last: classified, OK
    loop.image(now + 1.1, ask.stamp, metres)
    loop.health.step(now + 1.1, 5.0)  # the node's outputs report the step
    assert loop.report(now + 1.1)[0] == "OK"


def test_with_tf_an_image_past_the_transforms_is_refused_not_paired_with_an_earlier_pose(camera):
    loop = tf_loop(pose_tolerance=10.0)  # an earlier image's pose would be near enough by the tolerance
    ask = loop.start(0.0)[0]
    metres, position, rotation = camera.capture(ask.position, ask.rotation)
    loop.pose(0.1, "object", ask.stamp, position, rotation)
    assert any(isinstance(c, Step) for c in loop.image(0.1, ask.stamp, metres))  # its own transform
    ask = [c for c in loop.tick(0.1) + [loop.ask(0.2)] if type(c).__name__ == "AskView"][-1]
    later = ask.stamp + 1.0  # TF's newest transform is a second older than this image
    loop.image(later, later, camera.capture(ask.position, ask.rotation)[0])
    out = loop.tick(later + 0.3)
    assert loop.counts["classified"] == 1 and loop.counts["unmatched"] == 1
    assert "depth image refused: no transform cam -> object (Lookup would require extrapolation)" in out[0].reason


@pytest.mark.parametrize("offset, why", [(0.0, "0 m from the object's centre"), (0.03, "inside the object's box")])
def test_with_tf_a_camera_at_the_objects_centre_is_refused_by_name(camera, offset, why):
    loop = tf_loop()
    ask = loop.start(0.0)[0]
    metres, _, rotation = camera.capture(ask.position, ask.rotation)
    loop.image(0.1, ask.stamp, metres)
    refused = loop.pose(0.1, "object", ask.stamp, np.array([offset, 0.0, 0.0]), rotation)
    assert refused[0].reason.startswith("TF's camera transform refused: ") and why in refused[0].reason
    out = loop.tick(0.35)  # past pose_wait: the image is refused, saying why
    assert loop.counts["classified"] == 0 and why in out[0].reason


def test_an_object_frame_tf_never_had_ends_the_episode_no_frame_past_pose_wait():
    loop = tf_loop()
    loop.start(0.0)
    why = "TF has never had the object frame 'nowhere'"
    assert loop.frame_missing(0.15, why) == [] and loop.running  # it may still come
    refused, end = loop.frame_missing(0.25, why)
    assert why in refused.reason and "pose_wait (0.2 s)" in refused.reason
    assert end.result["status"] == "no_frame" and end.result["label"] == "" and not loop.running
    assert loop.frame_missing(0.3, why) == []  # ended once
