# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""The shared multi-view classifier (view pooling, as MV-CNN): it scores every planner's views
with one classifier, so that planners are compared by the views they choose, not by their own
recurrent classifiers. Trained on random views of the training split, neutral to every planner."""
from __future__ import annotations

import copy
import hashlib
import sys

import numpy as np
import torch
from torch import nn
from tqdm import tqdm

from active_recognition.argument_checks import InputError, input_file
from active_recognition.model import checkpoint
from active_recognition.model.network import compact_encoder
from active_recognition.sensing import geometry


# how a judge is trained: a cached one trained otherwise is trained again
RECIPE = "15 epochs, then 5 at a time while the validation score rises by 0.01"


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


def train_shared(shapes, num_classes, epochs=15, batch=32, max_views=10, seed=0, progress=True, val=None,
                 more=5, gain=0.01, max_epochs=60):
    """Train on random view sets (1..max_views views) of every training shape, `epochs` epochs.
    With `val` (the validation split's Shapes), it then goes on `more` epochs at a time for as
    long as that raises its validation score (`validation_score`) by `gain` or more, up to
    `max_epochs`, and keeps the last state that did: a judge that has not yet learnt a benchmark (the twins
    turned by an unknown yaw) gets the time it needs; one that has is left as it was."""
    torch.manual_seed(seed)
    rng = np.random.default_rng(seed)
    batch = min(batch, len(shapes))  # fewer shapes than a batch: one batch of them all, not none
    net = MultiViewClassifier(num_classes)
    opt = torch.optim.Adam(net.parameters(), 1e-3)
    best = state = None
    for epoch in range(max_epochs if val is not None else epochs):
        order = rng.permutation(len(shapes))
        bar = tqdm(range(0, len(order) - batch + 1, batch),
                   desc=f"shared classifier {epoch + 1}/{epochs}{'' if val is None else '+'}",
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
        done = epoch + 1
        if val is None or done < epochs or (done - epochs) % more:
            continue
        score = validation_score(net.eval(), val, max_views, seed)
        net.train()
        if progress:
            print(f"shared classifier: validation score {score:.3f} after {done} epochs", file=sys.stderr)
        if best is not None and score < best + gain:
            break
        best, state = score, copy.deepcopy(net.state_dict())
    if state is not None:
        net.load_state_dict(state)
    return net.eval()


def validation_score(net, val, max_views=10, seed=0):
    """Mean accuracy over 1..max_views of each validation shape's seeded random views."""
    rng = np.random.default_rng([seed, 7])
    hits = []
    with torch.no_grad():
        for b in range(0, len(val), 32):
            idx = np.arange(b, min(len(val), b + 32))
            depth = np.stack([c.render(geometry.random_views(rng, max_views)) for c in val.cameras(idx)])
            pred = net.prefix_logits(torch.from_numpy(depth)).argmax(-1).numpy()    # (B, V)
            hits.append(pred == val.labels[idx][:, None])
    return float(np.concatenate(hits).mean())


def fingerprint(shapes):
    """What a shared classifier was trained on: the camera (size, radius, field of view) and the
    training shapes themselves (count, and three meshes' vertices, turned by any yaw) and the
    RECIPE, so a cached one is not used after a generator, the yaw, the model's camera or the way
    judges train changed."""
    n, c = len(shapes), shapes.camera
    h = hashlib.sha256(f"{n} {c.height}x{c.width} r{c.radius!r} fov{c.fov_rad!r} {RECIPE}".encode())
    for i in sorted({0, n // 2, n - 1}):
        h.update(np.ascontiguousarray(shapes.mesh(i)[0], dtype=np.float32).tobytes())
    return h.hexdigest()


def load_or_train(path, shapes, classes, given=False, **kwargs):
    """The shared classifier at `path`, trained and saved there first if missing, or if it was
    trained on other shapes or through another camera (`fingerprint`). A `given` file (the
    user's --judge) is never trained over: InputError unless it fits."""
    key = fingerprint(shapes)
    if given:
        input_file(path, "judge")
    if path.exists():
        try:
            ckpt = checkpoint.read_any(path)
            if ckpt.get("classes") == list(classes) and checkpoint.nonfinite(ckpt["model"]) is None \
                    and ckpt.get("trained_on") == key:
                net = MultiViewClassifier(len(classes))
                net.load_state_dict(ckpt["model"])
                return net.eval()
            stale = "was trained on other shapes, through another camera or by another recipe"
        except (checkpoint.CheckpointError, RuntimeError, TypeError) as e:  # a damaged cache
            stale = f"is not usable ({str(e)[:200]})"
        if given:
            raise InputError(f"judge {path} {stale}: leave out --judge to train one in --out")
        print(f"{path} {stale}: training it again", file=sys.stderr)
    net = train_shared(shapes, len(classes), **kwargs)
    checkpoint.save(path, {"model": net.state_dict(), "model_args": {}, "classes": list(classes),
                           "kind": "shared_multiview", "trained_on": key})
    return net
