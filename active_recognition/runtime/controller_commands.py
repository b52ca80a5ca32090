# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""What the recognizer's loop (controller.Controller) tells its node to do: ask for a view,
publish a step, end an episode, refuse an input. Plain data, no ROS: the node turns each into
messages."""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np


@dataclass(frozen=True)
class AskView:
    """Publish next_view: the camera pose (metres, optical rotation) in `frame`, stamped `stamp`."""

    position: np.ndarray
    rotation: np.ndarray
    frame: str
    stamp: float
    again: bool  # the same view once more (a resend, or after an empty image)


@dataclass(frozen=True)
class Step:
    """Publish a classified image: its Observation, with the image's header and arrival, and the
    views taken so far (recognition/views)."""

    obs: Any                 # recognizer.Observation
    header: Any              # the image's (the node's message header; opaque here)
    arrived: float           # the caller's mark of the image's arrival (its step latency)
    next_view: AskView | None  # the request that follows it, None when the episode ends
    travel: float            # radians turned about the object between the views so far
    elapsed: float           # seconds since the start, pauses not counted
    goal: Any
    views: Any = ()          # (theta, phi) of each view taken so far
    standoff: float = 0.0    # metres from the object's centre to the camera of the next view
    frame: str = "object"    # the episode's object frame


@dataclass(frozen=True)
class End:
    """An episode ended: publish its result (a status of recognizer.Observation, or canceled)."""

    obs: Any
    header: Any              # the last classified image's, None when none was
    result: dict             # recognition/result's JSON fields, travel and elapsed among them
    goal: Any                # the goal it answers (None: ~/reset)
    replaced: bool = False   # canceled by the start of another (recognition/result stays silent)
    frame: str = "object"    # the episode's object frame


@dataclass(frozen=True)
class Refuse:
    """An input refused (counted under `key`; the node logs `reason`, throttled per key)."""

    key: str
    reason: str
