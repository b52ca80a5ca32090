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

"""Pictures for people: depth-image grids (PNG) written atomically."""
from __future__ import annotations

import os
import tempfile
from pathlib import Path

import numpy as np


def atomic_path(path):
    """A temp file beside `path`; rename it onto `path` once written (see `replace`)."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=path.suffix)
    os.close(fd)
    return Path(tmp)


def save_figure(fig, path, **kwargs):
    """Save a matplotlib figure as PNG with write-then-rename."""
    tmp = atomic_path(path)
    try:
        fig.savefig(tmp, format="png", **kwargs)
        os.chmod(tmp, 0o644)  # mkstemp makes 0600; a figure is for everyone to read
        os.replace(tmp, path)
    finally:
        tmp.unlink(missing_ok=True)


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
