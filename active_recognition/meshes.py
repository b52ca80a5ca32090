"""Load a mesh file and normalise it into [-0.5, 0.5]^3, with one clear error for bad files."""
from __future__ import annotations

import os
import re
from pathlib import Path

import numpy as np
import trimesh

from .validation import InputError

SUFFIXES = (".off", ".obj", ".ply", ".stl", ".glb")


class MeshError(InputError):
    """A mesh file that cannot be used; the message names the file and the reason."""

    def __init__(self, path, reason):
        super().__init__(f"{path}: {reason}")
        self.path, self.reason = str(path), reason


def normalise(vertices):
    """Centre the bounding box at the origin and scale its longest side to 1."""
    v = np.asarray(vertices, dtype=np.float64)
    lo, hi = v.min(0), v.max(0)
    size = float((hi - lo).max())
    if not np.isfinite(size) or size <= 0:
        raise ValueError("mesh has zero extent (all vertices coincide) or non-finite vertices")
    return (v - (lo + hi) / 2) / size


def read_off(path):
    """Parse OFF text, including the fused header of ModelNet ('OFF3514 3546 0') and polygons."""
    tokens = re.sub(r"#[^\n]*", " ", Path(path).read_text(errors="strict")).split()
    if not tokens or not tokens[0].upper().startswith("OFF"):
        raise ValueError("not an OFF file (no OFF header)")
    head = tokens[0][3:]
    tokens = ([head] if head else []) + tokens[1:]
    try:
        nv, nf = int(tokens[0]), int(tokens[1])
        vals = np.array(tokens[3:], dtype=object)
        if nv <= 0 or nf <= 0:
            raise ValueError(f"OFF header declares {nv} vertices and {nf} faces")
        verts = np.array(vals[:3 * nv], dtype=np.float64).reshape(nv, 3)
        pos, faces = 3 * nv, []
        for _ in range(nf):
            k = int(vals[pos])
            idx = [int(i) for i in vals[pos + 1:pos + 1 + k]]
            if k < 3 or len(idx) != k:
                raise ValueError(f"face with {k} corners")
            faces.extend([idx[0], idx[i], idx[i + 1]] for i in range(1, k - 1))  # fan
            pos += 1 + k
    except (IndexError, ValueError) as e:
        raise ValueError(f"truncated or malformed OFF ({e})") from None
    return verts, np.array(faces, dtype=np.int64)


def load_mesh(path):
    """Read a mesh file -> (vertices (V, 3) float32 in [-0.5, 0.5]^3, faces (F, 3) int32).

    Raises MeshError naming the file and the reason for anything unusable.
    """
    path = Path(path)
    suffix = path.suffix.lower()
    if suffix not in SUFFIXES:
        raise MeshError(path, f"unsupported format {suffix!r} (use one of {', '.join(SUFFIXES)})")
    if not path.is_file():
        raise MeshError(path, "no such file")
    if os.path.getsize(path) == 0:
        raise MeshError(path, "file is empty")
    try:
        if suffix == ".off":
            verts, faces = read_off(path)
        else:
            mesh = trimesh.load(path, force="mesh", process=False)
            verts, faces = np.asarray(mesh.vertices), np.asarray(mesh.faces)
    except MeshError:
        raise
    except Exception as e:  # trimesh raises many types for bad files
        raise MeshError(path, f"unreadable: {e}") from None
    return check_mesh(path, verts, faces)


def check_mesh(path, verts, faces):
    """Validate and normalise a parsed mesh; MeshError if degenerate."""
    verts, faces = np.asarray(verts), np.asarray(faces)
    if verts.ndim != 2 or verts.shape[1] != 3 or len(verts) < 3:
        raise MeshError(path, "fewer than 3 vertices")
    if faces.ndim != 2 or faces.shape[1] != 3 or len(faces) == 0:
        raise MeshError(path, "no triangle faces")
    if faces.min() < 0 or faces.max() >= len(verts):
        raise MeshError(path, "face indices outside the vertex list")
    if not np.isfinite(verts).all():
        raise MeshError(path, "non-finite vertex coordinates")
    tri = verts[faces]
    area = np.linalg.norm(np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]), axis=1)
    if not (area > 0).any():
        raise MeshError(path, "degenerate: every face has zero area")
    try:
        verts = normalise(verts)
    except ValueError as e:
        raise MeshError(path, str(e)) from None
    return verts.astype(np.float32), faces[area > 0].astype(np.int32)
