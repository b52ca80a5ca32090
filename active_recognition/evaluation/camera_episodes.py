# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""Episodes as the recognizer node runs them: a simulated camera (simulated_camera.py) shoots
each view the recognizer asks for, and ActiveRecognizer.observe reprojects the image into the
model's camera. The model's own renders (evaluate.rollout) and these differ a little, pixel by
pixel (another standoff, then reprojection), which the class answer hardly feels and the
distance of the recurrent state to its class mean does: open_set_fit fits the `unknown` answer
on these where asked (--camera), and benchmarks/open_set_camera.py measures it through them.

Each object is shown at its own size where its dataset knows it (else 1 m), kept within SIZES, a
household object's, and the recognizer is told it: a tenth of ModelNet10's files are drawn in
other units (a 115 m bathtub), and the RealSense preset, at the standoff where an object fills
its image, loses a 0.1 m cup inside its least range and a 5 m airplane beyond its greatest.
"""
from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from active_recognition.simulation.depth_sensor import SimulatedCamera, sensor_config

SIZES = (0.3, 3.0)  # metres the objects are shown within
# the statuses that name a class as the answer (unsure: below the node's confidence, its best guess
# read as before it had a status of its own); unknown and the failures count as wrong
ANSWERED = ("recognized", "unsure")


@dataclass
class CameraRun:
    """One episode: its last observation's status and whether it named the right class, per
    classified image its energy and prototype score (the recognizer's open-set evidence), and per
    image the class probabilities and the recurrent state (recorded only where asked)."""

    status: str
    label: int  # the object's true class
    right: bool
    score: float  # the running unknown score at the end, the checkpoint's own (NaN where none was taken)
    probs: list
    states: list
    energies: list
    prototypes: list
    views: np.ndarray | None = None  # (V, 2) the views the images were taken from, in turn
    size: float = 1.0  # metres: the object's size as shown and told to the recognizer


def recording_core(path, planner, steps, seed=0, use_size=True, travel_cost=None):
    """A recognizer with the node's view limits and sensing whose episodes are recorded whole:
    `steps` images each, no entropy stop, no hold and no `unknown` answer (the evidence of every
    step is kept: CameraRun); travel_cost: the imitation planner's (default: the node's)."""
    from active_recognition.model.episode import EpisodeConfig
    from active_recognition.options.recognizer_params import RecognizerParameters
    from active_recognition.runtime.active_recognizer import ActiveRecognizer

    node = RecognizerParameters()
    sensing = replace(node.sensing, use_size=use_size, unknown_threshold=0.0, hold_unknown=False)
    cost = node.episode.travel_cost if travel_cost is None else travel_cost
    return ActiveRecognizer(str(path), EpisodeConfig(steps, 0.0, cost), seed, planner, sensing, node.limits)


def shown_size(ds, i):
    """The size (metres) item i of ds is shown at: its own, else 1 m, kept within SIZES."""
    return min(max(ds.size(int(i)) or 1.0, SIZES[0]), SIZES[1])


def camera_runs(core, ds, name, split, objects, preset, seed, root=None, record=False):
    """A CameraRun per object of dataset `ds` (opened as `name`/`split`, under `root`) through
    simulated camera `preset` (a preset's name or a SensorConfig), each from a seeded initial view
    among the recognizer's."""
    sensor = sensor_config(preset) if isinstance(preset, str) else preset
    k = sensor.intrinsics()
    rng = np.random.default_rng(seed)
    runs = []
    for i in objects:
        size = shown_size(ds, i)
        sim = SimulatedCamera(replace(sensor, object_size=size * sensor.object_size), seed=seed * 100003 + int(i))
        sim.load(dataset=name, split=split, index=int(i), root=root or "")
        core.reset(view=core.initial_views[rng.integers(len(core.initial_views))],
                   sensing=replace(core.sensing, object_size=size))
        obs, probs, states = None, [], []
        while not core.done:
            shot = sim.capture(*core.requested_pose(k))
            if shot is None:  # below the floor: no image, as when an arm cannot get there
                core.view_unreachable()
                continue
            obs = core.observe(shot[0], k, shot[1], shot[2])
            if record and obs.probs is not None:
                probs.append(obs.probs)
                states.append(core.episode.hidden[0].detach().cpu().numpy().copy())
        label = ds.items[int(i)][1]
        truth, scores = ds.classes[label], core.open_set_scores()
        runs.append(CameraRun(obs.status if obs is not None else "no_image", label,
                              obs is not None and obs.status in ANSWERED and obs.label == truth,
                              float(np.mean(scores)) if scores else float("nan"),
                              probs, states, list(core.energies), list(core.prototypes), core.views_taken(), size))
    return runs


def robot_cost(runs, clock=None):
    """{views, travel_deg, robot_s, robot_s_p90} of CameraRuns: mean views, mean travel (degrees),
    and the mean and p90 robot seconds by `clock` (robot_time.RobotTime; default its defaults)."""
    from active_recognition.runtime.robot_time import RobotTime
    from active_recognition.sensing.geometry import travel

    clock = clock or RobotTime()
    seconds = np.array([clock.seconds(r.views) for r in runs])
    return {"views": float(np.mean([len(r.views) for r in runs])),
            "travel_deg": float(np.mean([np.degrees(travel(r.views)) for r in runs])),
            "robot_s": float(seconds.mean()), "robot_s_p90": float(np.percentile(seconds, 90))}


def full_length(runs, steps):
    """(probs (N, steps, C), states (N, steps, S)) of the runs that took `steps` images."""
    whole = [r for r in runs if len(r.probs) >= steps]
    return (np.stack([np.stack(r.probs[:steps]) for r in whole]),
            np.stack([np.stack(r.states[:steps]) for r in whole]), whole)
