# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""A dataset split as the renderer sees it: one depth camera per shape, built when first asked for."""
from __future__ import annotations

import numpy as np

from active_recognition.datasets.augment import Augment
from active_recognition.sensing.depth_layer import CameraConfig, DepthCamera
from active_recognition.sensing.meshes import box_edge, yaw_matrix, yawed


class Shapes:
    """A dataset split with one lazily built DepthCamera per shape, or with `augment` (and an
    rng) a fresh camera around an augmented copy of each shape. With `yaw` (degrees) each shape
    is turned about z by its own seeded yaw, uniform within +-yaw, its box re-fitted (objects
    whose heading a detector knows only roughly)."""

    def __init__(self, ds, camera: CameraConfig, yaw=0.0, seed=0):
        self.ds, self.camera, self._cams = ds, camera, {}
        self.labels = ds.labels()
        self.yaws = None
        if yaw:
            rng = np.random.default_rng([seed, len(ds), *map(ord, ds.split)])
            self.yaws = np.radians(rng.uniform(-yaw, yaw, len(ds)))

    def mesh(self, i):
        """(vertices, faces) of shape i, turned by its yaw."""
        vertices, faces = self.ds.mesh(i)
        return (vertices, faces) if self.yaws is None else (yawed(vertices, self.yaws[i]), faces)

    def __len__(self):
        return len(self.ds)

    def sizes(self, idx):
        """(len(idx),) the objects' longest box edges in metres (with a yaw, of the box
        re-fitted around the turned object, as a detector would give it), or None where the
        dataset does not know its objects' sizes."""
        out = []
        for i in idx:
            size = self.ds.size(i)
            if size is None:
                return None
            if self.yaws is not None:  # the turned unit box's longest side, times the size
                size *= box_edge(self.ds.mesh(i)[0] @ yaw_matrix(self.yaws[i]))
            out.append(size)
        return np.array(out)

    def cameras(self, idx, augment: Augment | None = None, rng=None):
        """The cameras of shapes idx; with `augment` (and rng) each around a fresh augmented copy
        of its shape: the shape's own camera posed by the draw (its scene is built once)."""
        for i in idx:
            if i not in self._cams:
                self._cams[i] = DepthCamera(*self.mesh(i), self.camera)
        if augment is not None and augment.meshes:
            return [augment.camera(self.mesh(i)[0], None, self.camera, rng, base=self._cams[i]) for i in idx]
        return [self._cams[i] for i in idx]
