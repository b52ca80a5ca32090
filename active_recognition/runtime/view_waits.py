# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""Where each view's time went, as the recognizer's loop (controller.py) saw it: waiting for the
image (from the view's first request to its image's arrival: the camera's latency, the
network's, and any request sent again), waiting for that image's pose (from its arrival to its
pose's), and computing (the step through the model). Per episode for its result, and over the
recent views for /diagnostics. No ROS: the caller passes its clock's seconds."""
from __future__ import annotations

from collections import deque

import numpy as np

RECENT = 200  # views /diagnostics' percentiles are over
PARTS = ("image", "pose", "compute")


class ViewWaits:
    def __init__(self, recent=RECENT):
        self.recent = deque(maxlen=recent)  # (image, pose, compute) seconds of the latest views
        self.episode = []                   # this episode's: {"stamp", "image", "pose", "compute"}

    def start(self):
        self.episode = []

    def view(self, stamp, asked, arrived, posed, compute):
        """A view classified: its image stamped `stamp` asked for at `asked`, arrived at `arrived`,
        its pose had at `posed` (the caller's clock, seconds), `compute` seconds of work."""
        parts = (max(arrived - asked, 0.0), max(posed - arrived, 0.0), compute)
        self.recent.append(parts)
        self.episode.append({"stamp": stamp, **dict(zip(PARTS, (round(p, 6) for p in parts)))})

    def values(self):
        """{key: value} for /diagnostics: p50 and p99 of each part over the recent views, in ms."""
        if not self.recent:
            return {f"view {part} wait p{q} (ms)": "none" for part in PARTS[:2] for q in (50, 99)}
        seconds = np.array(self.recent)
        return {f"view {part} wait p{q} (ms)": float(np.percentile(seconds[:, i], q)) * 1e3
                for i, part in enumerate(PARTS[:2]) for q in (50, 99)}
