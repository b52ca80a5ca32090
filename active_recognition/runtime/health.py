# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""The recognizer's health, as its /diagnostics reports it (no rclpy: testable alone).

Counts what happens (frames in, frames refused, steps and their latency, episodes by status) on
a monotonic clock the caller passes in, and decides the level:
- ERROR while the model is not loaded (configure failed: `error` says why);
- WARN when the latest image was refused for want of its transform (pose_source tf), ERROR from
  UNPOSED_ERROR of them in a row, no image classified between (within WINDOW_S of the latest):
  TF, not the camera, is named, with the frames;
- WARN during an episode when no image has come within view_timeout (the camera is silent), or
  when more than REFUSED_SHARE of the frames of the last WINDOW_S seconds were refused (at least
  MIN_FRAMES of them came);
- OK otherwise.
Rates and latency percentiles are over the last WINDOW_S seconds.
"""
from __future__ import annotations

from collections import Counter, deque

import numpy as np

WINDOW_S = 10.0       # seconds: rates, latency and the refused share are over this window
REFUSED_SHARE = 0.5   # WARN when more than this share of the window's frames were refused ...
MIN_FRAMES = 5        # ... and at least this many frames came in it
MAX_EVENTS = 100_000  # kept per kind within the window, whatever the frame rate
UNPOSED_ERROR = 3     # ERROR from so many images in a row refused for want of a transform (fewer: WARN)


class Health:
    def __init__(self, window=WINDOW_S, refused_share=REFUSED_SHARE, min_frames=MIN_FRAMES):
        self.window, self.refused_share, self.min_frames = window, refused_share, min_frames
        self.frames = deque(maxlen=MAX_EVENTS)    # arrival time of each frame
        self.refused = deque(maxlen=MAX_EVENTS)   # time of each frame refused
        self.steps = deque(maxlen=MAX_EVENTS)     # (time, step latency ms)
        self.episodes = Counter()                 # episodes ended, by status
        self.last_frame = None
        self.episode_since = None                 # start of the episode under way, else None
        self.unposed = (0, None, None)            # images in a row refused for want of a transform: (n, last time, why)

    def frame(self, now):
        self.frames.append(now)
        self.last_frame = now

    def refuse(self, now):
        self.refused.append(now)

    def step(self, now, ms):
        self.steps.append((now, ms))
        self.unposed = (0, None, None)

    def unposed_image(self, now, why):
        """An image refused for want of its transform (pose_source tf): `why` names the frames."""
        self.unposed = (self.unposed[0] + 1, now, why)

    def started(self, now):
        self.episode_since = now

    def ended(self, status):
        self.episode_since = None
        self.episodes[status] += 1

    def resumed(self, paused_for):
        """The node was inactive for `paused_for` seconds: the silence then is not the camera's."""
        if self.episode_since is not None:
            self.episode_since += paused_for
        if self.last_frame is not None:
            self.last_frame += paused_for

    def trim(self, now):
        start = now - self.window
        for events in (self.frames, self.refused):
            while events and events[0] < start:
                events.popleft()
        while self.steps and self.steps[0][0] < start:
            self.steps.popleft()

    def silent_for(self, now):
        """Seconds since the latest frame (or the episode's start, if later) during an episode;
        None between episodes."""
        if self.episode_since is None:
            return None
        latest = self.episode_since if self.last_frame is None else max(self.last_frame,
                                                                        self.episode_since)
        return now - latest

    def level(self, now, view_timeout, active=True, state="inactive"):
        """(level, message): 'OK' / 'WARN' / 'ERROR' and why. Not active (lifecycle `state`),
        nothing is expected."""
        self.trim(now)
        if not active:
            return "OK", f"{state}: images are ignored"
        n, at, why = self.unposed
        if n and now - at <= self.window:
            return "ERROR" if n >= UNPOSED_ERROR else "WARN", (
                f"TF: {n} image{'s' if n > 1 else ''} in a row refused for want of a transform ({why}); the "
                f"camera's images come: is its frame broadcast on TF, with the images' clock?")
        silent = self.silent_for(now)
        if silent is not None and silent > view_timeout:
            return "WARN", (f"no image for {silent:.1f} s during an episode (view_timeout "
                            f"{view_timeout:g} s): is the camera silent?")
        frames, refused = len(self.frames), len(self.refused)
        if frames >= self.min_frames and refused > self.refused_share * frames:
            return "WARN", (f"{refused} of {frames} frames refused in the last {self.window:g} s "
                            f"(more than {self.refused_share:.0%})")
        return "OK", "recognizing" if self.episode_since is not None else "waiting for ~/reset"

    def values(self, now):
        """{key: value} of the window and the totals, for the diagnostic status."""
        self.trim(now)
        ms = np.array([m for _, m in self.steps])
        values = {"image rate (Hz)": len(self.frames) / self.window,
                  f"frames refused (last {self.window:g} s)": len(self.refused),
                  f"frames (last {self.window:g} s)": len(self.frames),
                  "step latency p50 (ms)": float(np.percentile(ms, 50)) if len(ms) else "none",
                  "step latency p99 (ms)": float(np.percentile(ms, 99)) if len(ms) else "none"}
        values.update({f"episodes {status}": n for status, n in sorted(self.episodes.items())})
        return values


def unconfigured(failure, state):
    """(level, message, values) of a node with no loop: ERROR where configure failed (`failure`)."""
    if failure is not None:
        return "ERROR", f"configure failed, no model loaded: {failure}", {}
    return "OK", f"{state}: images are ignored", {}
