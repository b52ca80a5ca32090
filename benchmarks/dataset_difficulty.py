"""Does the procedural benchmark reward looking again? A small CNN on 32x32 depth, trained on
random views of the train split, scored on the test split with one random view and with nine
evenly spread views (log-probabilities summed). Last line: JSON with acc_1_view, acc_9_views."""
import argparse
import json
import time

import numpy as np
import torch
from torch import nn

from active_recognition import geometry
from active_recognition.datasets import open_dataset
from active_recognition.depth_layer import CameraConfig, DepthCamera


def render_set(ds, views_per_shape, rng, cfg):
    images, labels = [], []
    for i in range(len(ds)):
        cam = DepthCamera(*ds.mesh(i), cfg)
        views = views_per_shape(rng) if callable(views_per_shape) else views_per_shape
        images.append(cam.render(views))
        labels.append(ds.items[i][1])
    return torch.from_numpy(np.stack(images)) / 255.0, torch.tensor(labels)


def small_cnn(classes):
    return nn.Sequential(
        nn.Conv2d(1, 16, 3, padding=1), nn.ReLU(), nn.MaxPool2d(2),
        nn.Conv2d(16, 32, 3, padding=1), nn.ReLU(), nn.MaxPool2d(2),
        nn.Conv2d(32, 64, 3, padding=1), nn.ReLU(), nn.MaxPool2d(2),
        nn.Flatten(), nn.Linear(64 * 16, 128), nn.ReLU(), nn.Linear(128, classes))


def main():
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--views-per-shape", type=int, default=12, help="training views per shape")
    ap.add_argument("--epochs", type=int, default=8)
    ap.add_argument("--seed", type=int, default=0)
    args = ap.parse_args()
    torch.manual_seed(args.seed)
    rng = np.random.default_rng(args.seed)
    cfg = CameraConfig(height=32, width=32)
    t0 = time.perf_counter()
    train, test = open_dataset("procedural", split="train"), open_dataset("procedural", split="test")
    x, y = render_set(train, lambda r: geometry.random_views(r, args.views_per_shape), rng, cfg)
    x, y = x.reshape(-1, 1, 32, 32), y.repeat_interleave(args.views_per_shape)
    print(f"rendered {len(x)} training images in {time.perf_counter() - t0:.1f} s")
    net = small_cnn(len(train.classes))
    opt = torch.optim.Adam(net.parameters(), 1e-3)
    for epoch in range(args.epochs):
        perm = torch.randperm(len(x))
        for b in range(0, len(x), 128):
            idx = perm[b:b + 128]
            loss = nn.functional.cross_entropy(net(x[idx]), y[idx])
            opt.zero_grad()
            loss.backward()
            opt.step()
        print(f"epoch {epoch}: loss {loss.item():.3f}")
    net.eval()
    with torch.no_grad():
        x1, y1 = render_set(test, lambda r: geometry.random_views(r, 1), rng, cfg)
        acc1 = (net(x1.reshape(-1, 1, 32, 32)).argmax(1) == y1).float().mean().item()
        x9, y9 = render_set(test, geometry.fibonacci_views(9), rng, cfg)
        logp = net(x9.reshape(-1, 1, 32, 32)).log_softmax(1).reshape(len(y9), 9, -1).sum(1)
        acc9 = (logp.argmax(1) == y9).float().mean().item()
    print(json.dumps({"acc_1_view": round(acc1, 4), "acc_9_views": round(acc9, 4),
                      "gap": round(acc9 - acc1, 4), "test_shapes": len(test),
                      "seconds": round(time.perf_counter() - t0, 1)}))


if __name__ == "__main__":
    main()
