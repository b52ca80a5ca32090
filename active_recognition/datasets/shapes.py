# Copyright 2026 active_recognition maintainers
#
# Licensed under the Apache License, Version 2.0 (the "License");
# you may not use this file except in compliance with the License.
# You may obtain a copy of the License at
#
#     http://www.apache.org/licenses/LICENSE-2.0
#
# Unless required by applicable law or agreed to in writing, software
# distributed under the License is distributed on an "AS IS" BASIS,
# WITHOUT WARRANTIES OR CONDITIONS OF ANY KIND, either express or implied.
# See the License for the specific language governing permissions and
# limitations under the License.

"""A dataset split as the renderer sees it: one depth camera per shape, built when first asked for."""
from __future__ import annotations

from ..augment import Augment
from ..depth_layer import CameraConfig, DepthCamera


class Shapes:
    """A dataset split with one lazily built DepthCamera per shape, or with `augment` (and an
    rng) a fresh camera around an augmented copy of each shape."""

    def __init__(self, ds, camera: CameraConfig):
        self.ds, self.camera, self._cams = ds, camera, {}
        self.labels = ds.labels()

    def __len__(self):
        return len(self.ds)

    def cameras(self, idx, augment: Augment | None = None, rng=None):
        if augment is not None and augment.meshes:
            return [augment.camera(*self.ds.mesh(i), self.camera, rng) for i in idx]
        for i in idx:
            if i not in self._cams:
                self._cams[i] = DepthCamera(*self.ds.mesh(i), self.camera)
        return [self._cams[i] for i in idx]
