# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""The recognizer node's episode loop, without ROS: timestamped events in, commands out.

Events: an image, a camera_info, a pose, a tick of the node's timer, a start (~/reset, a goal),
a cancel, a pause and a resume (its lifecycle), new timing (retime), TF's word on a missing
transform or object frame. It is configured by its constructor and changed by events alone.
Commands: ask for a view (`next_view`), publish a step (an image's classification), end an
episode with its status, refuse an input with its reason. Times are the caller's clock in
seconds (the node's ROS clock, that of the stamps; a test's simulated one). States: idle,
waiting (a view asked for), classifying (an image waits for its pose), paused (the node
inactive), ended. An unanswered request is sent again max_retries times, then its view is given
up for another (no view left: no_image); an episode still under way episode_timeout after its
start (pauses not counted) ends with timeout."""
from __future__ import annotations

import time
from collections import Counter, deque
from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from active_recognition.argument_checks import InputError
from active_recognition.runtime.controller_commands import AskView, End, Refuse, Step
from active_recognition.runtime.health import Health
from active_recognition.runtime.robot_time import RobotTime
from active_recognition.runtime.timing import Timing
from active_recognition.runtime.view_waits import ViewWaits
from active_recognition.sensing import camera_input_bounds
from active_recognition.sensing.geometry import Intrinsics, travel

IDLE, WAITING, CLASSIFYING, PAUSED, ENDED = "idle", "waiting", "classifying", "paused", "ended"
IMAGE_COUNTS = ("received", "classified", "matched", "empty", "stale")  # as "images <count>"
FIRST_POSE_TRIES = 10  # tries of a view before any pose came (camera/pose has a publisher), within pose_wait


@dataclass
class Pending:
    """An image waiting for the camera pose of its stamp (since: when the wait began; a newer
    image keeps it, and the two it replaced: older, in case their late poses come first)."""

    stamp: float
    metres: np.ndarray
    k: Intrinsics | None
    since: float
    arrived: float
    header: Any
    older: tuple = ()


class Controller:
    """One object at a time on `core` (recognizer.ActiveRecognizer), its poses from camera/pose
    or, with `pose_source` "tf", from TF alone (an image without its measured pose is refused)."""

    def __init__(self, core, timing=Timing(), frame="object", cost=RobotTime(), pose_source="topic"):
        self.core, self.timing, self.frame, self.default_frame = core, timing, frame, frame
        self.require_pose = pose_source == "tf"
        # where the poses come from, for the refusals (with TF: why the waiting image has none yet)
        self.pose_from = "transform of the image's frame from TF" if self.require_pose else "camera/pose"
        self.state, self.goal, self.header = IDLE, None, None
        self.k, self.info_refused = None, None  # the latest camera_info, or why it was refused
        self.poses = deque(maxlen=200)          # (stamp, position, optical rotation)
        self.expect_poses = True                # until an image has waited in vain for its pose
        self.pending, self.request = None, None  # Pending; the request's stamp
        self.unposed = None                     # why the view's latest image had no transform (TF)
        self.asked_at, self.tries = None, 0     # when the view was (last) asked for; how often
        self.started = self.paused_at = None
        self.paused_for, self.resumed_state = 0.0, None
        self.counts, self.health = Counter(), Health()
        self.waited = deque(maxlen=1000)        # seconds each image waited for its pose
        self.view_waits = ViewWaits()           # each view's wait for its image, its pose; compute
        self.cost, self.budget = cost, 0.0      # what views cost a robot; this episode's budget
        self.notes = []                         # one-off information the node logs once

    # --- events -----------------------------------------------------------------------------

    def start(self, now, goal=None, frame="", object_size=0.0, max_views=0, sensing=None, time_budget=0.0):
        """A new object (~/reset, or a goal): ends the episode under way (canceled), asks the
        first view. Empty/zero arguments keep the node's settings. The stop rule: it stops below
        entropy_threshold (with a time budget: budget_entropy_threshold), after max_views, or
        before the view that would overrun its budget (over_budget)."""
        self.budget = float(time_budget) or self.timing.time_budget
        out = [replace(end, replaced=True) for end in self.cancel(now)]
        if object_size:
            sensing = replace(sensing or self.core.sensing, object_size=float(object_size))
        self.core.reset(sensing=sensing, max_views=max_views,
                        entropy_threshold=self.timing.budget_entropy_threshold if self.budget else None)
        self.frame = frame or self.default_frame
        self.goal, self.header, self.pending, self.request = goal, None, None, None
        self.started, self.paused_for, self.state = now, 0.0, WAITING
        self.health.started(now)
        self.view_waits.start()
        return out + [self.ask(now)]

    def cancel(self, now):
        """End the episode under way at once (status canceled, the best guess so far kept)."""
        if not self.running:
            return []
        self.pending = None
        return [self.end(now, self.core.so_far("canceled"))]

    def pause(self, now):
        """The node stops answering (deactivate): the episode waits, its time stopped."""
        if self.state != PAUSED:
            self.resumed_state, self.state, self.paused_at = self.state, PAUSED, now
            self.pending = self.asked_at = None
        return []

    def resume(self, now):
        """The node answers again (activate): an episode under way asks its view again."""
        if self.state != PAUSED:
            return []
        paused, self.state = now - self.paused_at, self.resumed_state
        self.paused_for += paused
        self.health.resumed(paused)
        self.state = WAITING if self.state == CLASSIFYING else self.state  # its view asked again
        return [self.ask(now)] if self.running else []

    def info(self, now, k=None, refused=None):
        """A camera_info: its intrinsics, or why it was refused (images then wait for one that passes)."""
        if refused is not None:
            self.k, self.info_refused = None, refused
            return [Refuse("depth/camera_info", f"camera_info refused: {refused}")]
        try:
            self.k, self.info_refused = camera_input_bounds.check_intrinsics(k), None
        except ValueError as e:
            return self.info(now, refused=str(e))
        return []

    def pose(self, now, frame, stamp, position, rotation):
        """A camera pose in `frame`, stamped `stamp` (from camera/pose, or TF's): kept, and an image
        waiting for it goes on."""
        name = "TF's camera transform" if self.require_pose else "camera/pose"
        try:
            if frame != self.frame:
                raise InputError(f"camera/pose header.frame_id {frame!r} is not the object frame "
                                 f"{self.frame!r} (parameter frame_id, or the goal's object_frame)")
            stamp = camera_input_bounds.check_clock(stamp, now, self.timing.max_clock_offset, name)
            camera_input_bounds.check_camera_position(position, name)
            size = self.core.sensing.object_size
            camera_input_bounds.check_outside_box(position, self.core.centre * size, size, name)
        except ValueError as e:
            if self.require_pose:  # the image waiting for it is refused by this name at pose_wait
                self.pose_from = f"usable transform from TF (the one for its stamp was refused: {e})"
            return [Refuse("camera/pose", f"{name} refused: {e}")]
        self.poses.append((stamp, np.asarray(position, float), np.asarray(rotation, float)))
        self.expect_poses = True
        for waiting in (self.pending, *self.pending.older) if self.state == CLASSIFYING else ():
            found = self.pose_at(waiting.stamp)
            if found is not None:
                self.pending = waiting
                self.waited.append(now - waiting.since)
                return self.classify(now, found)
        return []

    def image(self, now, stamp, metres=None, header=None, arrived=None, refused=None):
        """Classify a depth image stamped `stamp` (metres, NaN = no return; or why the node
        could not read it) now, or keep it until the pose of its stamp comes."""
        self.counts["received"] += 1
        self.health.frame(now)
        if self.state in (IDLE, ENDED, PAUSED):
            self.counts["idle"] += 1
            return []
        try:
            stamp = camera_input_bounds.check_clock(stamp, now, self.timing.max_clock_offset)
        except InputError as e:
            return self.reject(now, str(e))
        # fresh: stamped at or after the request (1 us spared for the stamp's round trip)
        if self.timing.require_fresh_images and self.request is not None and \
                stamp < self.request - 1e-6:
            self.counts["stale"] += 1
            return []  # taken before the camera reached the requested view
        if refused is not None:
            return self.reject(now, refused)
        k = self.k
        if k is None and self.info_refused:
            return self.reject(now, f"the latest camera_info was refused ({self.info_refused}): "
                                    f"waiting for one that passes")
        if k is None:
            self.note("info", "no CameraInfo on depth/camera_info yet: assuming the model's own "
                              "camera (its field of view at the image's size)")
        elif (k.height, k.width) != metres.shape:
            return self.reject(now, f"image is {metres.shape[1]}x{metres.shape[0]} but the "
                                    f"camera_info is for {k.width}x{k.height}")
        since = self.pending.since if self.pending is not None else now
        older = () if self.pending is None else (replace(self.pending, older=()), *self.pending.older)
        self.pending = Pending(stamp, metres, k, since, now if arrived is None else arrived, header,
                               older[:2])
        found = self.pose_at(stamp)
        if found is None and (self.expect_poses or self.require_pose):  # it may still be on its way
            # a newer image replaces the waiting one but not its wait: with no poses at all, a
            # 30 Hz camera would otherwise restart the wait forever
            self.state = CLASSIFYING
            return []
        if found is not None:
            self.waited.append(now - since)  # none when its pose was there already
        return self.classify(now, found)

    def tick(self, now, pose_publishers=False):
        """The node's timer: a late pose given up or asked again (late_pose), a timeout."""
        if not self.running or self.state == PAUSED:
            return []
        out = []
        if self.state == CLASSIFYING and now - self.pending.since > self.timing.pose_wait:
            # with TF, its transform at the stamp or none: never a kept pose of an earlier image
            found = None if self.require_pose else self.pose_at(self.pending.stamp, final=True)
            self.waited.append(now - self.pending.since)  # in vain, unless a near pose will do
            if found is None and self.require_pose:
                self.pending, self.state = None, WAITING
                self.counts["unmatched"] += 1
                self.unposed = f"no {self.pose_from} for its stamp within pose_wait ({self.timing.pose_wait:g} s)"
                self.health.unposed_image(now, self.unposed)
                out += self.reject(now, self.unposed)
            elif not self.poses:
                self.expect_poses = False
                self.note("pose", "no camera/pose received: assuming each image is taken at the "
                                  "requested view")
            elif found is None:
                out.append(Refuse("pose_wait", f"no camera/pose within pose_tolerance "
                                               f"({self.timing.pose_tolerance:g} s) of the image's "
                                               f"stamp came within pose_wait ({self.timing.pose_wait:g} "
                                               f"s): assuming the requested view"))
            if self.state == CLASSIFYING:
                out += self.classify(now, found)
        elif self.state == CLASSIFYING and self.late_pose(now, pose_publishers):
            self.counts["reasked"] += 1  # the same view: the camera's next pose brings the lost one
            out.append(self.ask(now, again=True))
        if self.running and self.elapsed(now) > self.timing.episode_timeout:
            self.pending = None
            out.append(Refuse("episode_timeout", f"the episode ran past episode_timeout "
                                                 f"({self.timing.episode_timeout:g} s) after "
                                                 f"{self.core.episode.steps} views: it ends with "
                                                 f"timeout"))
            return out + [self.end(now, self.core.time_out())]
        return out + self.check_view(now)

    def transform_missing(self, why):
        """TF cannot give the waiting image's transform yet (`why`): the refusal names it if none comes."""
        self.pose_from = why

    def frame_missing(self, now, why):
        """TF has never had the episode's object frame (`why` says which): past pose_wait from
        the episode's start, it ends with no_frame."""
        if not self.running or self.state == PAUSED or self.elapsed(now) <= self.timing.pose_wait:
            return []
        self.pending = None
        return [Refuse("no_frame", f"{why} within pose_wait ({self.timing.pose_wait:g} s) of the episode's "
                                   f"start: it ends with no_frame"), self.end(now, self.core.so_far("no_frame"))]

    def retime(self, timing, cost):
        """Runtime parameters changed: the episode under way goes on with this timing and cost."""
        self.timing, self.cost = timing, cost
        return []

    def report(self, now, active=True, state="active"):
        """(level, message, values) of the loop for /diagnostics: its health, counts and timing."""
        level, message = self.health.level(now, self.timing.view_timeout, active, state)
        values = {**self.health.values(now), **{f"images {k}": self.counts[k] for k in IMAGE_COUNTS},
                  "images matched to a measured pose (%)": 100.0 * self.counts["matched"] / max(
                      self.counts["classified"] + self.counts["unmatched"], 1),
                  "pose wait p99 (ms)": float(np.percentile(self.waited, 99)) * 1e3 if self.waited else "none",
                  **self.view_waits.values(), "requests resent": self.counts["resent"],
                  "views asked again for a late pose": self.counts["reasked"],
                  "views unreachable": self.counts["unreachable"],
                  "view_timeout (s)": self.timing.view_timeout,
                  "episode_timeout (s)": self.timing.episode_timeout}
        return level, message, values

    # --- the loop's own steps ---------------------------------------------------------------

    @property
    def running(self):
        """An episode is under way (paused or not)."""
        return self.state in (WAITING, CLASSIFYING) or \
            (self.state == PAUSED and self.resumed_state in (WAITING, CLASSIFYING))

    def elapsed(self, now):
        end = self.paused_at if self.state == PAUSED else now
        return end - self.started - self.paused_for if self.started is not None else 0.0

    def travel(self):
        return travel(self.core.views_taken())

    def note(self, key, text):
        self.notes.append((key, text))

    def ask(self, now, again=False):
        """The request for the core's next view (`again`: the same one once more)."""
        position, rotation = self.core.requested_pose(self.k)
        if not again:  # an answer to any try of this view is fresh
            self.request, self.tries, self.unposed = now, 0, None
        self.tries += 1
        self.asked_at = now
        return AskView(position, rotation, self.frame, now, again)

    def late_pose(self, now, pose_publishers=False):
        """Whether the waiting image, answering the latest request, waited pose_reask for its pose
        since the latest image; never with TF's (late, not lost) or 0, nor before a first pose
        unless camera/pose has a `pose_publishers` (a driver's first pose lost beside its frame)."""
        wait, asked, first = self.timing.pose_reask, self.asked_at, pose_publishers and self.tries < FIRST_POSE_TRIES
        return bool(wait and (self.poses or first)) and not self.require_pose and asked is not None and \
            self.pending.stamp >= asked - 1e-6 and now - self.health.last_frame >= wait

    def reject(self, now, reason):
        self.counts["rejected"] += 1
        self.health.refuse(now)
        return [Refuse("depth/image", f"depth image refused: {reason}")]

    def pose_at(self, stamp, final=False):
        """(position, rotation) of the pose stamped like the image, else the nearest within
        pose_tolerance; None while none is that near. Until `final`, a pose stamped after the
        image must have arrived too (the image's own may still be on its way)."""
        best = min(self.poses, key=lambda p: abs(p[0] - stamp), default=None)
        if best is None or abs(best[0] - stamp) > self.timing.pose_tolerance:
            return None
        if not final and best[0] != stamp and max(p[0] for p in self.poses) < stamp:
            return None
        return best[1:]

    def classify(self, now, found):
        """The waiting image through the core, with its pose (None: the view asked for)."""
        p, self.pending, self.state, self.unposed = self.pending, None, WAITING, None
        try:
            began = time.perf_counter()
            obs = self.core.observe(p.metres, p.k, *(found or (None, None)))
        except InputError as e:  # the image itself (its shape); a bug elsewhere is not an input
            return self.reject(now, str(e))
        self.asked_at = None  # answered
        if obs.status == "empty":
            self.counts["empty"] += 1
            return [Refuse("empty", f"no object in the image ({obs.object_fraction:.2%} of the "
                                    f"model's pixels): asking for the same view again"),
                    self.ask(now)]
        out, last = [], obs if obs.done else None
        if obs.status != "no_object":
            self.counts["classified"] += 1
            self.counts["matched"] += found is not None  # to its measured pose
            self.view_waits.view(p.stamp, self.request, p.since, now, time.perf_counter() - began)
            self.header = p.header
            if last is None and self.over_budget():
                last = self.core.finish()  # the next view would overrun the budget: answer now
            ask = None if last is not None else self.ask(now)
            out += [ask] if ask is not None else []
            taken = self.core.views_taken()  # once: its travel and recognition/views' markers
            out.append(Step(obs, p.header, p.arrived, ask, travel(taken), self.elapsed(now), self.goal,
                            taken, self.core.standoff(self.k), self.frame))
        if last is not None:
            out.append(self.end(now, last))
        return out

    def check_view(self, now):
        """Send a request no usable image answered within view_timeout again; after max_retries
        resends give its view up (the core picks another, or ends the episode: no_image)."""
        if self.asked_at is None or self.state != WAITING or \
                now - self.asked_at < self.timing.view_timeout:
            return []
        view = "({:.0f}, {:.0f}) deg".format(*np.degrees(self.core.view))
        if self.unposed:  # the camera answered: TF did not
            view += f" (its images came, but TF had no transform for them: {self.unposed})"
        if self.tries <= self.timing.max_retries:
            self.counts["resent"] += 1
            return [Refuse("view_timeout", f"no usable image for view {view} within view_timeout "
                                           f"({self.timing.view_timeout:g} s): asking again (try "
                                           f"{self.tries + 1} of {self.timing.max_retries + 1})"),
                    self.ask(now, again=True)]
        self.counts["unreachable"] += 1
        obs = self.core.view_unreachable()
        if obs.done:
            return [Refuse("no_image", f"view {view} unreachable after {self.tries} tries: no "
                                       f"view can be had ({self.core.sensing.max_unreachable_views} "
                                       f"unreachable in a row, or none left); the episode ends "
                                       f"with no_image"), self.end(now, obs)]
        other = "({:.0f}, {:.0f}) deg".format(*np.degrees(self.core.view))
        if self.over_budget():  # the view in its place would overrun the budget: answer now
            return [Refuse("unreachable", f"view {view} unreachable after {self.tries} tries; {other} "
                                          f"in its place would overrun the time budget: answering now"),
                    self.end(now, self.core.finish())]
        return [Refuse("unreachable", f"view {view} unreachable after {self.tries} tries: asking "
                                      f"for {other} instead"), self.ask(now)]

    def over_budget(self):
        """Whether the episode's next view (core.view, as asked) would overrun its time budget
        (never before the first view, nor without a budget)."""
        taken = self.core.views_taken()
        return bool(self.budget) and len(taken) > 0 and \
            self.cost.seconds(taken) + self.cost.next_view(taken, self.core.view) > self.budget

    def end(self, now, obs):
        result = {**obs.result(), "travel": self.travel(), "elapsed": self.elapsed(now),
                  "robot_seconds": self.cost.seconds(self.core.views_taken()),
                  "view_waits": self.view_waits.episode}
        end = End(obs, self.header, result, self.goal, frame=self.frame)
        self.health.ended(obs.status)
        self.state, self.goal, self.request, self.asked_at = ENDED, None, None, None
        self.frame = self.default_frame  # a goal's object frame is for its episode alone
        return end
