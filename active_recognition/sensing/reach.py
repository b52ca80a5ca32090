# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""The views a robot can take: an elevation band of the viewing sphere, less the views it failed.

Elevation is measured in the object frame (z up) from the plane through the object's centre:
90 - theta in degrees (geometry.py's theta is the angle from +z). An object on a floor or table
is never seen from below (`min_elevation` >= 0 by the nodes' default); the whole sphere, the
paper's setting, is -90..90. Candidate-based planners mask the candidates outside the band;
continuous ones are clamped into it (Episode.step). The initial views are the paper's evenly
spread views that lie in the band. Views a robot could not reach (`block`) are not asked for
again: a planner's choice near one becomes the nearest free initial view.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from active_recognition.argument_checks import InputError, option, validate
from active_recognition.sensing import geometry

BLOCK_RADIUS = math.radians(14.0)  # a view this near a blocked one is blocked (half the spacing
#                                    of the 50 initial views)


@dataclass(frozen=True)
class ViewLimits:
    min_elevation: float = option(-90.0, lo=-90, hi=90, help=(
        "degrees above the plane through the object's centre (object frame, z up): no view from "
        "lower; -90 = the whole sphere (the paper's), 0 suits an object on a floor or table"))
    max_elevation: float = option(90.0, lo=-90, hi=90, help="degrees: no view from higher; 90 = "
                                                            "from straight above")

    def __post_init__(self):
        validate(self)
        if self.min_elevation > self.max_elevation:
            raise InputError(f"min_elevation ({self.min_elevation:g}) must not exceed "
                             f"max_elevation ({self.max_elevation:g})")

    @property
    def whole_sphere(self):
        return self.min_elevation <= -90 and self.max_elevation >= 90

    def theta_range(self):
        """(lowest, highest) theta in radians: theta = 90 degrees - elevation."""
        return math.radians(90 - self.max_elevation), math.radians(90 - self.min_elevation)

    def allows(self, views):
        """(N,) bool: views (N, 2) inside the band (a tolerance of 1e-6 rad)."""
        lo, hi = self.theta_range()
        theta = np.asarray(views, dtype=np.float64).reshape(-1, 2)[:, 0]
        return (theta >= lo - 1e-6) & (theta <= hi + 1e-6)

    def clamp(self, views):
        """views (..., 2), numpy or torch, with theta clamped into the band (differentiable
        where not clamped); phi is kept."""
        if self.whole_sphere:
            return views
        lo, hi = self.theta_range()
        if hasattr(views, "detach"):  # torch
            import torch
            return torch.stack([views[..., 0].clamp(lo, hi), views[..., 1]], -1)
        views = np.array(views, dtype=np.float64)
        views[..., 0] = np.clip(views[..., 0], lo, hi)
        return views

    def initial_views(self, n=50):
        """The paper's n evenly spread views (geometry.fibonacci_views) that lie in the band, (k, 2);
        when none does (a narrow band), the n views clamped into it."""
        views = geometry.fibonacci_views(n)
        inside = views[self.allows(views)]
        return inside if len(inside) else self.clamp(views)

    def random_views(self, rng, n):
        """n views uniform on the band of the sphere, (n, 2), from a numpy Generator."""
        lo, hi = self.theta_range()
        z = rng.uniform(math.cos(hi), math.cos(lo), n)
        return np.stack([np.arccos(z), rng.uniform(-math.pi, math.pi, n)], -1)


def angles_between(views, others):
    """(N, M) angles (radians) between views (N, 2) and others (M, 2) on the sphere."""
    a = geometry.camera_position(*np.asarray(views, dtype=np.float64).reshape(-1, 2).T)
    b = geometry.camera_position(*np.asarray(others, dtype=np.float64).reshape(-1, 2).T)
    return np.arccos(np.clip(a @ b.T, -1.0, 1.0))


class Reach:
    """ViewLimits plus the views found unreachable in this episode (a robot's; B = 1)."""

    def __init__(self, limits: ViewLimits = ViewLimits(), candidates=50):
        self.limits = limits
        self.candidates = limits.initial_views(candidates)
        self.blocked = np.zeros((0, 2))

    def reset(self):
        self.blocked = np.zeros((0, 2))

    def block(self, view):
        """Never ask for `view` (theta, phi), or a view within BLOCK_RADIUS of it, again."""
        self.blocked = np.concatenate([self.blocked, np.asarray(view, np.float64).reshape(1, 2)])

    def allows(self, views):
        """(N,) bool: views (N, 2) in the band and not near a blocked view."""
        views = np.asarray(views, dtype=np.float64).reshape(-1, 2)
        ok = self.limits.allows(views)
        if len(self.blocked):
            ok &= angles_between(views, self.blocked).min(1) > BLOCK_RADIUS
        return ok

    def free_candidates(self, visited=()):
        """The initial views still allowed, those not near a view in `visited` first: (k, 2)."""
        free = self.candidates[self.allows(self.candidates)]
        if len(free) and len(visited):
            new = angles_between(free, visited).min(1) > BLOCK_RADIUS
            if new.any():
                return free[new]
        return free

    def keep(self, views, visited=()):
        """views (B, 2) clamped into the band; one near a blocked view replaced by the nearest
        free candidate (unvisited if any; `visited` (M, 2), or a function giving them, called
        only then), kept when none is left (the caller ends the episode: `free_candidates` is
        empty). Torch views stay torch (differentiable where untouched)."""
        views = self.limits.clamp(views)
        rows = views.detach().cpu().numpy() if hasattr(views, "detach") else np.asarray(views)
        rows = np.asarray(rows, dtype=np.float64).reshape(-1, 2)
        bad = ~self.allows(rows)
        if not bad.any():
            return views
        free = self.free_candidates(visited() if callable(visited) else visited)
        if not len(free):
            return views
        nearest = free[angles_between(rows[bad], free).argmin(1)]
        if hasattr(views, "detach"):
            import torch
            views = views.clone()
            views[torch.as_tensor(bad)] = torch.as_tensor(nearest, dtype=views.dtype,
                                                          device=views.device)
            return views
        out = rows.copy()
        out[bad] = nearest
        return out


def reach_of(limits: ViewLimits | None):
    """A fresh Reach for an episode (or a batch of them) within `limits`; None for the whole
    sphere (None too), where there is nothing to keep to."""
    return None if limits is None or limits.whole_sphere else Reach(limits)
