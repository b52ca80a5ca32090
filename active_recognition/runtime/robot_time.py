# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""What views cost a robot, in seconds: a capture for each view, a settle after each move, and
the camera's travel about the object at a steady angular speed (the great-circle angle between
successive views). A camera on an arm pays for a view in seconds, not in views."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from active_recognition.argument_checks import option, validate
from active_recognition.sensing.geometry import travel


@dataclass
class RobotTime:
    capture_s: float = option(0.1, lo=0, hi=60, runtime=True, help=(
        "robot seconds to take one depth image once the camera is there"))
    settle_s: float = option(0.5, lo=0, hi=60, runtime=True, help=(
        "robot seconds for the arm to settle after each move"))
    rad_per_s: float = option(0.5, lo=1e-3, hi=100, runtime=True, help=(
        "the camera's angular speed about the object, radians per robot second"))

    def __post_init__(self):
        validate(self)

    def seconds(self, views):
        """Robot seconds of views (N, 2) (theta, phi) taken in turn: N captures, N - 1 moves."""
        n = len(np.asarray(views).reshape(-1, 2))
        return n * self.capture_s + max(n - 1, 0) * self.settle_s + travel(views) / self.rad_per_s

    def next_view(self, views, view):
        """The robot seconds one more view at `view` adds after views (N, 2): a move (none for the
        first view) and a capture."""
        views = np.asarray(views, dtype=np.float64).reshape(-1, 2)
        if not len(views):
            return self.capture_s
        return self.settle_s + travel(np.stack([views[-1], view])) / self.rad_per_s + self.capture_s
