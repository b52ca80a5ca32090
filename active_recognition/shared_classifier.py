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

"""The shared multi-view classifier (view pooling, as MV-CNN): it scores every planner's views
with one classifier, so that planners are compared by the views they choose, not by their own
recurrent classifiers. Trained on random views of the training split, neutral to every planner."""
from __future__ import annotations

import hashlib
import sys

import numpy as np
import torch
from torch import nn
from tqdm import tqdm

from . import checkpoint, geometry
from .model import compact_encoder


class MultiViewClassifier(nn.Module):
    def __init__(self, num_classes, feature_size=256):
        super().__init__()
        self.encoder = compact_encoder(feature_size)
        self.classify = nn.Linear(feature_size, num_classes)

    def view_features(self, depth):
        """depth (B, V, 64, 64) in [0, 255] -> per-view features (B, V, F)."""
        b, v = depth.shape[:2]
        return self.encoder(1.0 - depth.reshape(b * v, 1, *depth.shape[2:]) / 255.0).reshape(b, v, -1)

    def forward(self, depth):
        """depth (B, V, 64, 64) in [0, 255] -> logits (B, C), features max-pooled over views."""
        return self.classify(self.view_features(depth).amax(1))

    def prefix_logits(self, depth):
        """Logits of every prefix views[:t], t = 1..V: (B, V, C), each view encoded once."""
        return self.classify(torch.cummax(self.view_features(depth), dim=1).values)


def train_shared(shapes, num_classes, epochs=15, batch=32, max_views=10, seed=0, progress=True):
    """Train on random view sets (1..max_views views) of every training shape."""
    torch.manual_seed(seed)
    rng = np.random.default_rng(seed)
    net = MultiViewClassifier(num_classes)
    opt = torch.optim.Adam(net.parameters(), 1e-3)
    for epoch in range(epochs):
        order = rng.permutation(len(shapes))
        bar = tqdm(range(0, len(order) - batch + 1, batch), desc=f"shared classifier {epoch + 1}/{epochs}",
                   disable=not progress, file=sys.stderr, leave=False)
        for b in bar:
            idx = order[b:b + batch]
            v = int(rng.integers(1, max_views + 1))
            depth = np.stack([c.render(geometry.random_views(rng, v)) for c in shapes.cameras(idx)])
            loss = nn.functional.cross_entropy(net(torch.from_numpy(depth)),
                                               torch.as_tensor(shapes.labels[idx]))
            opt.zero_grad()
            loss.backward()
            opt.step()
            bar.set_postfix(loss=f"{loss.item():.3f}")
    return net.eval()


def fingerprint(shapes):
    """What a shared classifier was trained on: the camera (size, radius, field of view) and the
    training shapes themselves (count, and three meshes' vertices, turned by any yaw), so a
    cached one is not used after a generator, the yaw or the model's camera changed."""
    n, c = len(shapes), shapes.camera
    h = hashlib.sha256(f"{n} {c.height}x{c.width} r{c.radius!r} fov{c.fov_rad!r}".encode())
    for i in sorted({0, n // 2, n - 1}):
        h.update(np.ascontiguousarray(shapes.mesh(i)[0], dtype=np.float32).tobytes())
    return h.hexdigest()


def load_or_train(path, shapes, classes, **kwargs):
    """The shared classifier at `path`, trained and saved there first if missing, or if it was
    trained on other shapes or through another camera (`fingerprint`)."""
    key = fingerprint(shapes)
    if path.exists():
        try:
            ckpt = checkpoint.read_any(path)
            if ckpt.get("classes") == list(classes) and checkpoint.nonfinite(ckpt["model"]) is None \
                    and ckpt.get("trained_on") == key:
                net = MultiViewClassifier(len(classes))
                net.load_state_dict(ckpt["model"])
                return net.eval()
            print(f"{path} was trained on other shapes or another camera: training it again",
                  file=sys.stderr)
        except (checkpoint.CheckpointError, RuntimeError, TypeError) as e:  # a damaged cache
            print(f"{path} is not usable ({str(e)[:200]}): training it again", file=sys.stderr)
    net = train_shared(shapes, len(classes), **kwargs)
    checkpoint.save(path, {"model": net.state_dict(), "model_args": {}, "classes": list(classes),
                           "kind": "shared_multiview", "trained_on": key})
    return net
