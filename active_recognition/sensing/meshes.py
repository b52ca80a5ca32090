# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""Load a mesh file and normalise it into [-0.5, 0.5]^3, with one clear error for bad files."""
from __future__ import annotations

import os
import re
from pathlib import Path

import numpy as np
import trimesh

from active_recognition.argument_checks import InputError

SUFFIXES = (".off", ".obj", ".ply", ".stl", ".glb")
TEXT = (".off", ".obj")  # text-only formats


class MeshError(InputError):
    """A mesh file that cannot be used; the message names the file and the reason. `kind` sorts
    the reasons for counting skipped files: 'empty', 'degenerate' (parsed, but no surface to
    see) or 'corrupt' (not a readable mesh of its format)."""

    KINDS = ("corrupt", "empty", "degenerate")

    def __init__(self, path, reason, kind="corrupt"):
        super().__init__(f"{path}: {reason}")
        assert kind in self.KINDS, kind
        self.path, self.reason, self.kind = str(path), reason, kind


def normalise(vertices):
    """Centre the bounding box at the origin and scale its longest side to 1."""
    v = np.asarray(vertices, dtype=np.float64)
    lo, hi = v.min(0), v.max(0)
    size = float((hi - lo).max())
    if not np.isfinite(size) or size <= 0:
        raise ValueError("mesh has zero extent (all vertices coincide) or non-finite vertices")
    return (v - (lo + hi) / 2) / size


def box_edge(vertices):
    """The longest edge of the vertices' (V, 3) axis-aligned bounding box."""
    v = np.asarray(vertices, dtype=np.float64)
    return float((v.max(0) - v.min(0)).max())


def yaw_matrix(yaw):
    """(3, 3) that turns row vectors by `yaw` radians about z (vertices @ it)."""
    c, s = np.cos(yaw), np.sin(yaw)
    return np.array([[c, s, 0], [-s, c, 0], [0, 0, 1]])


def yawed(vertices, yaw):
    """Vertices turned by `yaw` radians about z, their box re-fitted (`normalise`): the object
    in a frame of unknown heading, as a detector's axis-aligned box gives it."""
    return normalise(np.asarray(vertices, dtype=np.float64) @ yaw_matrix(yaw))


def parse_off(text):
    """Parse the text of an OFF file, including the fused header of ModelNet ('OFF3514 3546 0')
    and polygons (fanned into triangles) -> (vertices (V, 3) float64, faces (F, 3) int64). The
    tokens are converted by numpy in blocks, so a 4 MB ModelNet file parses in tens of
    milliseconds; tokens after the last face are ignored."""
    if "#" in text:
        text = re.sub(r"#[^\r\n]*", " ", text)
    tokens = text.split()
    if not tokens or not tokens[0].upper().startswith("OFF"):
        raise ValueError("not an OFF file (no OFF header)")
    head = tokens[0][3:]
    tokens = ([head] if head else []) + tokens[1:]
    try:
        nv, nf = int(tokens[0]), int(tokens[1])
        if nv <= 0 or nf <= 0:
            raise ValueError(f"OFF header declares {nv} vertices and {nf} faces")
        vals = tokens[3:]
        if len(vals) < 3 * nv:
            raise ValueError(f"header declares {nv} vertices but the file holds {len(vals) // 3}")
        verts = np.array(vals[:3 * nv], dtype=np.float64).reshape(nv, 3)
        faces = off_faces(vals[3 * nv:], nf)
    except (IndexError, ValueError) as e:
        raise ValueError(f"truncated or malformed OFF ({e})") from None
    return verts, faces


def off_faces(tokens, nf):
    """The `nf` faces of OFF face tokens ('k i1 .. ik' each) as fanned triangles (F, 3) int64."""
    if len(tokens) >= 4 * nf:  # the common case: all triangles, read as one (nf, 4) block
        try:
            block = np.array(tokens[:4 * nf], dtype=np.int64).reshape(nf, 4)
            if (block[:, 0] == 3).all():
                return block[:, 1:].copy()
        except ValueError:  # a token after the faces that is no integer: walk them instead
            pass
    starts, counts, pos = [], [], 0
    for n in range(nf):
        if pos >= len(tokens):
            raise ValueError(f"header declares {nf} faces but the file holds {n}")
        k = int(tokens[pos])
        if k < 3 or pos + 1 + k > len(tokens):
            raise ValueError(f"face with {k} corners")
        starts.append(pos + 1)
        counts.append(k - 2)
        pos += 1 + k
    idx = np.array(tokens[:pos], dtype=np.int64)
    start = np.repeat(np.array(starts), counts)  # (F,) where each triangle's face starts
    j = np.arange(len(start)) - np.repeat(np.cumsum([0] + counts[:-1]), counts) + 1  # 1 .. k-2
    return np.stack([idx[start], idx[start + j], idx[start + j + 1]], 1)  # the fan of each face


def load_mesh(path, edge=False):
    """Read a mesh file -> (vertices (V, 3) float32 in [-0.5, 0.5]^3, faces (F, 3) int32), and with
    `edge` the longest edge of its bounding box in the file's units (before normalising).

    Raises MeshError naming the file and the reason for anything unusable.
    """
    path = Path(path)
    suffix = path.suffix.lower()
    if path.is_dir():  # before the suffix: a folder has none, and is no mesh whatever its name
        raise MeshError(path, "is a directory, not a file")
    if suffix not in SUFFIXES:
        raise MeshError(path, f"unsupported format {suffix!r} (use one of {', '.join(SUFFIXES)})")
    if not path.is_file():
        raise MeshError(path, "no such file")
    if os.path.getsize(path) == 0:
        raise MeshError(path, "file is empty", "empty")
    try:
        text = sniff(path, suffix)
        if suffix == ".off":
            verts, faces = parse_off(text)
        else:
            mesh = trimesh.load(path, force="mesh", process=False)
            verts, faces = np.asarray(mesh.vertices), np.asarray(mesh.faces)
        if suffix == ".ply":
            check_ply_counts(path, len(verts), len(faces))
    except MeshError:
        raise
    except ImportError:  # trimesh guessing the encoding of undecodable text
        raise MeshError(path, f"unreadable: not a valid {suffix[1:].upper()} file") from None
    except Exception as e:  # trimesh raises many types for bad files
        raise MeshError(path, f"unreadable: {e}") from None
    out = check_mesh(path, verts, faces)
    return (*out, box_edge(verts)) if edge else out


def sniff(path, suffix):
    """MeshError when the file cannot be of its format: binary data in a text format, or a
    missing PLY, GLB or STL signature. Returns the text of a text format (read once)."""
    fmt = suffix[1:].upper()
    if suffix in TEXT:
        try:
            text = Path(path).read_bytes().decode("utf-8")
        except UnicodeDecodeError:
            raise MeshError(path, f"not a text {fmt} file (binary data, or not UTF-8)") from None
        if "\0" in text:
            raise MeshError(path, f"not a text {fmt} file (binary data)")
        return text
    with open(path, "rb") as f:
        head = f.read(1 << 16)
    if suffix == ".ply" and not head.startswith(b"ply"):
        raise MeshError(path, "not a PLY file (no 'ply' signature)")
    elif suffix == ".glb" and not head.startswith(b"glTF"):
        raise MeshError(path, "not a GLB file (no 'glTF' signature)")
    elif suffix == ".stl":
        size = os.path.getsize(path)
        count = int.from_bytes(head[80:84], "little") if size >= 84 else -1
        if size != 84 + 50 * count and not head.lstrip().lower().startswith(b"solid"):
            raise MeshError(path, "not an STL file (neither ASCII 'solid' nor binary STL of the "
                                  "length its triangle count implies)")


def check_ply_counts(path, vertices, faces):
    """MeshError when the PLY header declares more vertices or faces than were read."""
    with open(path, "rb") as f:
        header = f.read(1 << 16).split(b"end_header", 1)[0].decode("latin-1")
    declared = dict(re.findall(r"^element\s+(vertex|face)\s+(\d+)", header, re.M))
    nv, nf = int(declared.get("vertex", 0)), int(declared.get("face", 0))
    if vertices < nv or faces < nf:  # polygons become several triangles: faces may be more
        raise MeshError(path, f"header declares {nv} vertices and {nf} faces, the file holds "
                              f"{vertices} and {faces}: truncated")


def check_mesh(path, verts, faces):
    """Validate and normalise a parsed mesh; MeshError if degenerate."""
    verts, faces = np.asarray(verts), np.asarray(faces)
    if verts.ndim != 2 or verts.shape[1] != 3 or len(verts) < 3:
        raise MeshError(path, "fewer than 3 vertices", "degenerate")
    if faces.ndim != 2 or faces.shape[1] != 3 or len(faces) == 0:
        raise MeshError(path, "no triangle faces", "degenerate")
    if faces.min() < 0 or faces.max() >= len(verts):
        raise MeshError(path, "face indices outside the vertex list")
    if not np.isfinite(verts).all():
        raise MeshError(path, "non-finite vertex coordinates")
    scale = float(np.abs(verts).max()) or 1.0  # areas in units of the largest coordinate: no
    tri = verts[faces] / scale                # overflow for huge ones, no underflow for tiny ones
    area = np.linalg.norm(np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]), axis=1)
    if not (area > 0).any():
        raise MeshError(path, "degenerate: every face has zero area", "degenerate")
    try:
        verts = normalise(verts)
    except ValueError as e:
        raise MeshError(path, str(e), "degenerate") from None
    return verts.astype(np.float32), faces[area > 0].astype(np.int32)
