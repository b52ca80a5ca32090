# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""Pictures for people: depth-image grids (PNG) written atomically."""
from __future__ import annotations

import numpy as np

from .files import atomic_path


def plt():
    """matplotlib.pyplot on the Agg backend (no screen needed)."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as pyplot
    return pyplot


def save_figure(fig, path, **kwargs):
    """Save a matplotlib figure as PNG, atomically."""
    with atomic_path(path) as tmp:
        fig.savefig(tmp, format="png", **kwargs)


def depth_grid(images, path, titles=None, columns=None, row_labels=None):
    """Write a grid of normalised depth images (N, H, W) in [0, 255] as a PNG; None leaves a
    cell blank."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from .validation import InputError

    images = list(images)
    n = len(images)
    if all(image is None for image in images):
        raise InputError(f"{path}: no images to draw")
    columns = columns or int(np.ceil(np.sqrt(n)))
    rows = int(np.ceil(n / columns))
    fig, axes = plt.subplots(rows, columns, figsize=(1.6 * columns, 1.7 * rows), squeeze=False)
    for i, ax in enumerate(axes.flat):
        ax.set_axis_off()
        if i < n and images[i] is not None:
            ax.imshow(images[i], cmap="viridis", vmin=0, vmax=255)
            if titles is not None:
                ax.set_title(titles[i], fontsize=7)
    if row_labels is not None:
        for r, label in enumerate(row_labels):
            axes[r, 0].text(-0.1, 0.5, label, transform=axes[r, 0].transAxes, ha="right",
                            va="center", fontsize=8)
    fig.tight_layout()
    save_figure(fig, path, dpi=100)
    plt.close(fig)


def render_mesh(mesh, out, views=0, theta=1.047, phi=0.524, size=64, radius=1.0, fov=None):
    """Depth images of a mesh file as a PNG grid: `views` evenly spread views, or the one view
    (theta, phi). -> (number of views, share of pixels that hit the mesh)."""
    from . import geometry
    from .depth_layer import CameraConfig, DepthCamera
    from .meshes import load_mesh

    cam = DepthCamera(*load_mesh(mesh), CameraConfig(height=size, width=size, radius=radius, fov=fov))
    views = geometry.fibonacci_views(views) if views else np.array([[theta, phi]])
    depth = cam.render(views)
    depth_grid(depth, out, titles=[f"({t:.2f}, {p:.2f})" for t, p in views])
    return len(views), float((depth < 255).mean())


def readable_views(n):
    """A few readable views: the first n of front, side, top, below, three-quarter."""
    views = [(1.57, -1.57), (1.57, 0.0), (0.35, -1.57), (2.6, -1.2), (1.0, -0.8)]
    return np.array(views[:n])


def contact_sheet(name, root, splits, path, sheet_split="test", objects_per_class=2,
                  views_per_object=3, seed=0):
    """A row per class: objects_per_class test objects (train if the test split is empty), each
    from views_per_object views; cells stay blank where a class has fewer objects. The twins:
    each pair seen from a telling view and from one that is not."""
    from .depth_layer import DepthCamera

    if name == "twins":
        from .datasets.twins import pair_sheet
        images, labels, titles = pair_sheet(seed)
        depth_grid(images.reshape(-1, *images.shape[2:]), path, columns=4,
                   row_labels=labels, titles=titles * len(labels))
        return
    if sheet_split != "test":  # a generated benchmark's held-out styles
        from .datasets import open_dataset
        ds = open_dataset(name, root, sheet_split, cache_dir=splits["test"].cache_dir)
    else:
        ds = splits["test"] if len(splits["test"]) else splits["train"]
    rng, views = np.random.default_rng(seed), readable_views(views_per_object)
    images = []
    for label in range(len(ds.classes)):
        idx = np.flatnonzero(ds.labels() == label)
        row = [img for i in rng.choice(idx, min(objects_per_class, len(idx)), replace=False)
               for img in DepthCamera(*ds.mesh(i)).render(views)]
        images += row + [None] * (objects_per_class * len(views) - len(row))
    depth_grid(images, path, columns=objects_per_class * len(views), row_labels=ds.classes)
