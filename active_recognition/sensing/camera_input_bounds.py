# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""The bounds a real depth camera and a real camera pose keep: what a robot's input is checked
against before it reaches the core. Each refusal is an InputError naming the field and why."""
from __future__ import annotations

import math

import numpy as np

from active_recognition.argument_checks import InputError
from active_recognition.sensing.geometry import Intrinsics

FOV_DEG = (1.0, 170.0)      # a depth camera's field of view along either axis, degrees
ASPECT = (0.5, 2.0)         # fy / fx: pixels no further from square
CENTRE = (0.1, 0.9)         # the principal point within this share of the image on each axis
MAX_DISTANCE = 100.0        # metres: no depth camera sees an object from further


def check_intrinsics(k: Intrinsics, what="camera_info") -> Intrinsics:
    """k, if a real rectified camera could have it; else InputError naming the K entry."""
    for name, focal, size, axis in (("k[0] (fx)", k.fx, k.width, "wide"),
                                    ("k[4] (fy)", k.fy, k.height, "high")):
        fov = math.degrees(2 * math.atan(size / (2 * focal)))
        if not FOV_DEG[0] <= fov <= FOV_DEG[1]:
            raise InputError(f"{what} {name} = {focal:g} px gives a {fov:.3g}-degree field of view "
                             f"across {size} px {axis}; a depth camera's lies in "
                             f"{FOV_DEG[0]:g}..{FOV_DEG[1]:g} degrees")
    if not ASPECT[0] <= k.fy / k.fx <= ASPECT[1]:
        raise InputError(f"{what} k[4] (fy) = {k.fy:g} px is {k.fy / k.fx:.3g} x k[0] (fx); "
                         f"pixels are nearly square ({ASPECT[0]:g}..{ASPECT[1]:g})")
    for name, c, size in (("k[2] (cx)", k.cx, k.width), ("k[5] (cy)", k.cy, k.height)):
        if not CENTRE[0] * size <= c <= CENTRE[1] * size:
            raise InputError(f"{what} {name} = {c:g} px lies outside the middle of the "
                             f"{k.width}x{k.height} image ({CENTRE[0]:.0%}..{CENTRE[1]:.0%} of "
                             f"{size} px): the principal point of another image size?")
    return k


def check_camera_position(position, what="camera/pose") -> np.ndarray:
    """A camera position (3,) metres in the object frame, within MAX_DISTANCE of the object's
    centre and off it; else InputError naming the field."""
    position = np.asarray(position, dtype=np.float64)
    distance = float(np.linalg.norm(position))
    if not 1e-3 < distance <= MAX_DISTANCE:
        raise InputError(f"{what} pose.position is {distance:.3g} m from the object's centre; a "
                         f"camera that sees the object is 0.001..{MAX_DISTANCE:g} m from it")
    return position


def check_outside_box(position, centre, object_size, what="camera/pose") -> np.ndarray:
    """A camera position (3,) metres outside the object's box, else InputError naming the field.

    The box is the one the core keeps the object's points from (before box_margin): object_size
    along every axis, as the longest edge bounds each, about the object's centre as found so far
    (`centre`, metres: the object frame's origin until recentre moves it). A camera inside it
    would be inside the object, or closer to it than any view the model knows."""
    position = np.asarray(position, dtype=np.float64)
    offset = position - np.asarray(centre, dtype=np.float64)
    if np.all(np.abs(offset) < object_size / 2):
        raise InputError(
            f"{what} pose.position ({', '.join(f'{v:.3g}' for v in position)}) m lies inside the "
            f"object's box (edge {object_size:g} m, the parameter object_size, about its centre "
            f"({', '.join(f'{v:.3g}' for v in centre)}) m): a camera there is inside the object")
    return position


def check_clock(stamp, now, tolerance, what="depth/image"):
    """Seconds `stamp` within `tolerance` of the clock `now`; else InputError naming the stamp."""
    offset = stamp - now
    if abs(offset) > tolerance:
        raise InputError(f"{what} header.stamp is {offset:+.3g} s from this node's clock (more "
                         f"than max_clock_offset, {tolerance:g} s): another clock, or a replay "
                         f"without use_sim_time?")
    return stamp
