# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""Training augmentation for what a robot's object frame and depth camera get wrong.

Meshes (a new one per training episode):
- `yaw`: the object turned by a random yaw about z (uniform within +-`yaw_range` degrees: the
  whole turn by default), its box re-fitted (a detector's axis-aligned box in a frame of unknown
  or roughly known heading);
- `frame_error`: the box's centre off by up to that fraction of the object's size, in a random
  direction, and its size wrong by up to that fraction (as camera_robustness applies them);
  then cropped to the box plus `box_margin`, as the recognizer's reprojection crops;
- `floor_cut`: up to that fraction of the object's bottom cut away (a support plane cut too
  high leaves a ragged bottom);
- `mirror`: the chance that the object is mirrored left to right (x -> -x): a piece of
  furniture's mirror image is one of its class too (depths and the depth layer's gradient do not
  depend on the faces' winding, which is left as it is);
- `stretch`: each axis of the object scaled by its own factor within [1/(1+s), 1+s]
  (log-uniform), its box re-fitted: a table longer or a cabinet squatter than any seen in
  training is one of its class too (ModelNet10's test tables are longer than its training ones).
Images: `dropout`: up to that fraction of pixels missing (drawn per image), plus pixels on depth
edges dropped at the same rate (flying-pixel removal); missing pixels read as misses (255).
`steep`: the chance that an image loses, as a driver's flying-pixel filter removes them, every
pixel beside a jump to a 4-neighbour steeper than a surface seen 70-85 degrees from face-on
(simulated_camera.edge_dropout's rule, on the model's own camera: needs `view_camera`).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import torch

from active_recognition.sensing.meshes import normalise, yaw_matrix

MISS = 255.0


@dataclass
class Augment:
    yaw: bool = False
    frame_error: float = 0.0
    floor_cut: float = 0.0
    dropout: float = 0.0
    yaw_range: float = 180.0    # degrees (for `yaw`)
    box_margin: float = 0.1
    mirror: float = 0.0
    steep: float = 0.0
    stretch: float = 0.0
    view_camera: object = None  # depth_layer.CameraConfig of the images (for `steep`)

    def __post_init__(self):
        for name in ("frame_error", "floor_cut", "dropout", "stretch"):
            value = getattr(self, name)
            if not 0 <= value < 0.5:
                raise ValueError(f"augmentation {name} must lie in [0, 0.5), got {value}")
        if not 0 <= self.steep <= 1:
            raise ValueError(f"augmentation steep is a chance in [0, 1], got {self.steep}")
        if not 0 <= self.mirror <= 1:
            raise ValueError(f"augmentation mirror is a chance in [0, 1], got {self.mirror}")
        if not 0 < self.yaw_range <= 180:
            raise ValueError(f"augmentation yaw_range is in degrees, (0, 180], got {self.yaw_range}")
        if self.steep > 0 and self.view_camera is None:
            raise ValueError("augmentation steep needs the images' camera")

    @property
    def changes_images(self):
        return self.dropout > 0 or self.steep > 0

    @property
    def meshes(self):
        return (self.yaw or self.frame_error > 0 or self.floor_cut > 0 or self.mirror > 0
                or self.stretch > 0)

    def transform(self, vertices, rng):
        """The mesh's vertices in the frame a robot would give (turned, then off in centre and
        size), and the lower corner of the crop box (its bottom raised by the floor cut)."""
        v, lo, _ = self.draw(vertices, rng)
        return v, lo

    def draw(self, vertices, rng):
        """`transform`'s draw, with the map it is: (vertices', lo, (A, b)), vertices' = vertices
        A^T + b. Every step is affine, so a depth camera can cast its rays into the mesh's own
        frame instead of building a scene around the moved copy (`camera`'s base)."""
        v = np.asarray(vertices, dtype=np.float64)
        a, b = np.eye(3), np.zeros(3)

        def then(m, t=0.0):  # v -> v m + t (row vectors), composed into (a, b)
            nonlocal a, b
            a, b = m.T @ a, b @ m + t

        def refit():  # normalise's own centring and scale, taken from v's box
            lo, hi = v.min(0), v.max(0)
            size = float((hi - lo).max())
            then(np.eye(3) / size, -(lo + hi) / 2 / size)
            return normalise(v)

        if self.mirror and rng.random() < self.mirror:
            v = v * [-1.0, 1.0, 1.0]
            then(np.diag([-1.0, 1.0, 1.0]))
        if self.stretch > 0:
            scale = np.exp(rng.uniform(-1, 1, 3) * np.log1p(self.stretch))
            v = v * scale
            then(np.diag(scale))
            v = refit()
        if self.yaw:
            turn = yaw_matrix(rng.uniform(-1, 1) * np.radians(self.yaw_range))
            v = v @ turn
            then(turn)
            v = refit()
        if self.frame_error > 0:
            d = rng.standard_normal(3)
            off = rng.uniform(0, self.frame_error) * d / np.linalg.norm(d)
            believed = 1 + rng.uniform(-self.frame_error, self.frame_error)
            v = (v - off) / believed  # the object seen in the detector's (wrong) unit box
            then(np.eye(3) / believed, -off / believed)
        lo = np.full(3, -0.5 - self.box_margin)
        if self.floor_cut > 0:
            lo[2] = max(lo[2], v[:, 2].min() + rng.uniform(0, self.floor_cut) * np.ptp(v[:, 2]))
        return v, lo, (a, b)

    def camera(self, vertices, faces, config, rng, base=None):
        """A DepthCamera around one augmented copy of a normalised mesh, cropped like the
        recognizer's reprojection crops (hits outside the box are misses, as the points that
        the reprojection drops leave empty pixels). With `base` (a DepthCamera of that mesh) the
        copy is `base` posed by the draw's map (no scene built; the box's corners stand for the
        vertices where no yaw needs them all), else a camera around the moved vertices."""
        from active_recognition.sensing.depth_layer import DepthCamera
        high = np.full(3, 0.5 + self.box_margin, np.float32)
        if base is None:
            v, lo = self.transform(vertices, rng)
            cam = DepthCamera(v, faces, config)
        else:
            v = np.asarray(vertices)
            points = v if self.yaw else np.stack(np.meshgrid(*zip(v.min(0), v.max(0)), indexing="ij"), -1)
            _, lo, (a, b) = self.draw(points.reshape(-1, 3), rng)
            cam = base.posed(a, b)
        cam.crop = (lo.astype(np.float32), high)
        return cam

    def images(self, depth: torch.Tensor, generator: torch.Generator | None = None, rng=None):
        """Drop pixels of normalised depth (..., H, W): missing ones read as misses. The draws come
        from torch's `generator` (default: torch's own), or from numpy's Generator `rng` where
        given: the same distribution, in a sixteenth of the time for imitation's 1,600 candidate
        images, and safe on the thread that makes a batch ahead (it leaves torch's alone)."""
        if not self.changes_images:
            return depth
        shape = depth.shape
        flat = depth.reshape(-1, *shape[-2:])
        if self.steep > 0:
            flat = self.steep_removed(flat, generator, rng)
        if self.dropout <= 0:
            return flat.reshape(shape)
        rate = uniform((len(flat), 1, 1), generator, rng) * self.dropout
        drop = below(flat.shape, rate, generator, rng)
        d = flat.detach()
        jump = torch.zeros_like(drop)  # a depth edge: a neighbour more than 5 units away
        rows = (d[:, 1:, :] - d[:, :-1, :]).abs() > 5  # between vertical neighbours
        cols = (d[:, :, 1:] - d[:, :, :-1]).abs() > 5  # between horizontal neighbours
        jump[:, 1:, :] |= rows
        jump[:, :-1, :] |= rows
        jump[:, :, 1:] |= cols
        jump[:, :, :-1] |= cols
        drop |= jump & below(flat.shape, 2 * rate, generator, rng)
        return torch.where(drop.to(depth.device), torch.full_like(flat, MISS), flat).reshape(shape)

    def steep_removed(self, flat, generator=None, rng=None):
        """Per image, with chance `steep`: NaN-free copy of (N, H, W) normalised depth with the
        pixels beside a steep jump (simulated_camera.edge_dropout, on the model's camera, at a
        random angle in 70-85 degrees) set to misses; jumps to a miss do not count. Only the
        chosen images are looked at (half of imitation's 1,600 candidates a joint step at 0.5)."""
        n = len(flat)
        chosen = uniform((n, 1, 1), generator, rng) < self.steep
        angle = torch.deg2rad(70 + 15 * uniform((n, 1, 1), generator, rng))
        at = torch.nonzero(chosen.flatten()).flatten()
        out, on = flat.clone(), at.to(flat.device)
        out[on] = self.steep_pixels(flat[on], angle[at])
        return out

    def steep_pixels(self, flat, angle):
        """(N, H, W) normalised depth with every pixel beside a jump steeper than `angle` (N, 1, 1)
        radians from face-on set to a miss (each pixel judged by its own depth, as the driver)."""
        near, far = self.view_camera.depth_range
        scale = 255.0 / (far - near)
        focal = self.view_camera.intrinsics().fx
        d = flat.detach().cpu()
        z = near * scale + d  # metric z-depth x scale, in the normalised depth's units
        limit = torch.tan(angle) / focal * z
        hit = d < MISS
        drop = torch.zeros_like(hit)
        rows = (d[:, 1:, :] - d[:, :-1, :]).abs().masked_fill(~(hit[:, 1:, :] & hit[:, :-1, :]), 0)
        cols = (d[:, :, 1:] - d[:, :, :-1]).abs().masked_fill(~(hit[:, :, 1:] & hit[:, :, :-1]), 0)
        drop[:, 1:, :] |= rows > limit[:, 1:, :]
        drop[:, :-1, :] |= rows > limit[:, :-1, :]
        drop[:, :, 1:] |= cols > limit[:, :, 1:]
        drop[:, :, :-1] |= cols > limit[:, :, :-1]
        return torch.where(drop.to(flat.device), torch.full_like(flat, MISS), flat)


def uniform(shape, generator=None, rng=None):
    """Uniform [0, 1) float32 of `shape`: from numpy's Generator `rng`, else torch's `generator`."""
    if rng is None:
        return torch.rand(shape, generator=generator)
    return torch.from_numpy(rng.random(shape, dtype=np.float32))


def below(shape, chance, generator=None, rng=None):
    """Bool (shape): each True with probability `chance` (a tensor broadcasting to shape). With
    numpy's `rng`, from 16-bit draws (a resolution of 1/65,536)."""
    if rng is None:
        return torch.rand(shape, generator=generator) < chance
    limit = (chance.numpy() * 65536.0).astype(np.uint32)
    return torch.from_numpy(rng.integers(0, 65536, shape, dtype=np.uint16) < limit)
