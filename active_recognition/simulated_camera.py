"""The simulated depth camera's core: a mesh source and a render at any pose (no ROS here)."""
from __future__ import annotations

import math

import numpy as np

from .datasets import default_cache_dir, open_dataset
from .depth_layer import CameraConfig, DepthCamera, render_pose, sensor_noise
from .meshes import load_mesh


def load_object(mesh="", dataset="procedural", split="test", index=0, root=""):
    """(vertices, faces, description) of a mesh file, or of item `index` of a dataset split."""
    if mesh:
        return (*load_mesh(mesh), mesh)
    ds = open_dataset(dataset, root or None, split, cache_dir=default_cache_dir())
    if not 0 <= index < len(ds):
        raise ValueError(f"{dataset}/{split} has {len(ds)} objects; index {index} is out of range")
    return (*ds.mesh(index), f"{dataset}/{split}[{index}] ({ds.classes[ds.items[index][1]]})")


class SimulatedCamera:
    def __init__(self, config: CameraConfig, noise_std=0.0, dropout=0.0, seed=0):
        if noise_std < 0 or not 0 <= dropout < 1:
            raise ValueError("noise_std must be >= 0 and dropout in [0, 1)")
        self.config, self.noise_std, self.dropout = config, noise_std, dropout
        self.rng = np.random.default_rng(seed)
        self.camera, self.description = None, None

    def load(self, **source):
        """Switch to another object; on failure the previous one stays (the error propagates)."""
        verts, faces, description = load_object(**source)
        self.camera, self.description = DepthCamera(verts, faces, self.config), description

    def render(self, position, optical_rotation):
        """Metric depth (H, W), NaN = no return, with the configured sensor noise."""
        depth = render_pose(self.camera, position, optical_rotation)
        return sensor_noise(depth, self.rng, self.noise_std, self.dropout)


def camera_config(width, height, fov_deg, radius):
    return CameraConfig(height=height, width=width, radius=radius,
                        fov=math.radians(fov_deg) if fov_deg > 0 else None)
