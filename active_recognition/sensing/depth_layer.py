# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""The depth layer: ray-cast a mesh from a view into a depth image, and differentiate it.

`DepthCamera` holds one mesh in an embree scene. `trace` casts one ray per pixel and keeps the
hit table (distance, face normal) that the backward pass uses; `render` turns it into the paper's
normalised depth (0..255, 255 = miss) and `metric` into REP 118 depth in metres along the optical
axis (NaN = miss). `render_views` is the differentiable, batched form (a torch autograd Function)
with two gradient rules: "paper" (fixed hit point, METHOD.md) and "surface" (the ray/tangent-plane
intersection differentiated through the face normal: the true first-order derivative).
"""
from __future__ import annotations

import copy
import functools
import math
import threading
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass

import numpy as np
import torch
from embreex import rtcore, rtcore_scene
from embreex.mesh_construction import TriangleMesh

from active_recognition.argument_checks import InputError
from active_recognition.sensing import geometry

MISS = 255.0
GRADIENT_RULES = ("paper", "surface")
_POOL = ThreadPoolExecutor(max_workers=2)  # embree casts without the GIL: a worker per caller (--prefetch: 2)
# One embree device for every scene: a device per scene crashes after a few thousand meshes.
_DEVICE = rtcore.EmbreeDevice()
_SCRATCH = threading.local()  # per thread: the ray directions of its last one-view cast


@dataclass(frozen=True)
class CameraConfig:
    """Intrinsics and the viewing sphere. fov is horizontal, in radians; None = holds the cube."""

    height: int = 64
    width: int = 64
    radius: float = 1.0
    fov: float | None = None
    focal: float = 0.05  # the paper's f: distance from the camera to its projection plane

    def __post_init__(self):
        if not (1 <= self.height <= 4096 and 1 <= self.width <= 4096):
            raise InputError(f"camera size {self.height}x{self.width} must be 1..4096 pixels a side")
        if not (math.isfinite(self.radius) and self.radius > 0):
            raise InputError(f"camera radius must be a positive number, got {self.radius}")
        if self.fov is not None and not (0 < self.fov < math.pi):
            raise InputError(f"camera fov must lie in (0, pi) radians, got {self.fov}")
        if not (self.focal > 0):
            raise InputError(f"camera focal length must be positive, got {self.focal}")

    @property
    def fov_rad(self) -> float:
        return geometry.default_fov(self.radius) if self.fov is None else self.fov

    @property
    def depth_range(self):
        """(near, far) z-depth mapped to 0 and 255: the cube's bounding sphere seen from R."""
        return max(self.radius - geometry.CUBE_RADIUS, 0.0), self.radius + geometry.CUBE_RADIUS

    def intrinsics(self) -> geometry.Intrinsics:
        """This camera's K (square pixels, centred), for a CameraInfo or a reprojection."""
        return geometry.Intrinsics.from_fov(self.width, self.height, self.fov_rad)


def normalise_depth(z, config: CameraConfig):
    """Metric z-depth -> the paper's depth in [0, 255]; inf or NaN (no return) -> 255.

    The one place where metres become the network's input.
    """
    near, far = config.depth_range
    k = np.float32(255.0 / (far - near))
    d = np.asarray(z, dtype=np.float32) * k
    d -= np.float32(near) * k
    np.fmin(d, MISS, out=d)  # fmin takes the number where the other is NaN: NaN and inf -> 255
    return np.fmax(d, 0.0, out=d)


@dataclass
class Hits:
    """The hit table of one batch: per view and pixel, the ray and what it hit."""

    origins: np.ndarray     # (B, 3) camera positions
    rotations: np.ndarray   # (B, 3, 3) view rotations (t = 0 frame -> world)
    distance: np.ndarray    # (B, N) ray length to the hit, inf on a miss
    normals: np.ndarray | None  # (B, N, 3) unnormalised face normals (0 on a miss), mesh's frame; None: unasked
    normal_map: np.ndarray | None = None  # (3, 3) that brings them to the world's (a posed camera)

    def world_normals(self):
        """The face normals in the world's frame (B, N, 3) (a product per view: numpy's BLAS
        threads make one (B N, 3) x (3, 3) product crawl)."""
        return self.normals if self.normal_map is None else self.normals @ self.normal_map.T

    @property
    def hit(self):
        return np.isfinite(self.distance)


def ray_tables(x, y, focal):
    """Read-only rays of the pixels at projection-plane coordinates x (up), y (right), (H, W)
    each: unit directions in the t = 0 frame (forward -Z, up +X, right -Y) (N, 3) float64, their
    cosines to the optical axis (N,), and float32 copies, the directions transposed (3, N)."""
    local = np.stack([x, -y, np.full_like(x, -focal)], -1).reshape(-1, 3)
    cos = focal / np.linalg.norm(local, axis=1)  # f / sqrt(x^2 + y^2 + f^2)
    local_dirs = local * (cos / focal)[:, None]  # unit rays, (N, 3)
    tables = (local_dirs, cos, np.ascontiguousarray(local_dirs.T, dtype=np.float32),
              cos.astype(np.float32))
    for t in tables:
        t.flags.writeable = False
    return tables


@functools.lru_cache(maxsize=32)
def model_rays(config):
    """`ray_tables` of the model's virtual camera `config`, built once and shared by every
    DepthCamera of that config: per camera they were 192 KiB at 64x64, 740 MiB over ModelNet10's
    3,928 training scenes, nearly half of their memory."""
    x, y = geometry.pixel_grid(config.height, config.width, config.fov_rad, config.focal)
    return ray_tables(x, y, config.focal)


class DepthCamera:
    """A pinhole depth camera around one mesh normalised into [-0.5, 0.5]^3."""

    def __init__(self, vertices, faces, config: CameraConfig = CameraConfig(), intrinsics=None):
        vertices = np.asarray(vertices, dtype=np.float32)
        faces = np.asarray(faces, dtype=np.int32)
        if vertices.ndim != 2 or vertices.shape[1] != 3 or faces.ndim != 2 or faces.shape[1] != 3:
            raise InputError(f"mesh needs (V, 3) vertices and (F, 3) triangles, got "
                             f"{vertices.shape} and {faces.shape}")
        if len(faces) == 0 or faces.min() < 0 or faces.max() >= len(vertices):
            raise InputError("mesh has no faces or face indices outside its vertex list")
        self.config = config
        self.crop = None  # (lo (3,), hi (3,)): only hits inside this box count (augmentation)
        # posed: (A^-1, b, det(A) A^-T, A's diagonal or None) float32: the mesh seen moved, v -> A v + b
        self.pose = None
        self.scene = rtcore_scene.EmbreeScene(_DEVICE)
        TriangleMesh(self.scene, vertices, faces)
        if intrinsics is None:  # the same read-only tables for every camera of one config
            tables = model_rays(config)
        else:  # any K (a real camera's, for the simulated one); the image size is the config's
            if (intrinsics.height, intrinsics.width) != (config.height, config.width):
                raise InputError(f"intrinsics are for {intrinsics.width}x{intrinsics.height}, the "
                                 f"camera renders {config.width}x{config.height}")
            optical = intrinsics.rays() * config.focal
            tables = ray_tables(-optical[..., 1], optical[..., 0], config.focal)
        self.local_dirs, self.cos, self._dirs32_t, self._cos32 = tables

    @classmethod
    def from_mesh(cls, mesh, config: CameraConfig = CameraConfig()):
        return cls(mesh.vertices, mesh.faces, config)

    def posed(self, a, b):
        """A camera sharing this one's scene that sees the mesh moved by v -> a v + b (a (3, 3)
        invertible, b (3,)): each ray is cast into the mesh's own frame (o -> a^-1 (o - b),
        w -> a^-1 w: the same ray parameter, so the same distances) and each face normal brought
        back (n -> det(a) a^-T n, as embree's normal of the moved face), so no scene is built.
        The same hit table as a camera around the moved vertices, to float precision."""
        a = np.asarray(a, dtype=np.float64)
        inv = np.linalg.inv(a)
        cam = copy.copy(self)
        cam.crop = None
        inv, shift, normal_map = (np.ascontiguousarray(m, dtype=np.float32) for m in
                                  (inv, np.asarray(b, dtype=np.float64), np.linalg.det(a) * inv.T))
        diagonal = np.diag(a).astype(np.float32) if np.count_nonzero(a - np.diag(np.diag(a))) == 0 else None
        cam.pose = (inv, shift, normal_map, diagonal)
        return cam

    def trace(self, views, normals=True) -> Hits:
        """Cast the rays of views (B, 2) or (2,) on the sphere: the hit table (without the face
        normals, which only the view gradient reads, where `normals` is False)."""
        views = np.asarray(views, dtype=np.float64).reshape(-1, 2)
        rot = geometry.view_rotation(views[:, 0], views[:, 1])
        return self.trace_poses(rot[..., 2] * self.config.radius, rot, normals)  # R (0, 0, r)

    def trace_poses(self, origins, rotations, normals=True) -> Hits:
        """Cast rays from any poses: origins (B, 3), rotations (B, 3, 3) of the t = 0 frame;
        without `normals`, embree is asked for the distances alone (the same ones, a twelfth
        less time a cast: no normals, barycentrics or ids to write)."""
        origins = np.asarray(origins, dtype=np.float64).reshape(-1, 3)
        rotations = np.asarray(rotations, dtype=np.float64).reshape(-1, 3, 3)
        b, n = len(origins), len(self.local_dirs)
        rot32, orig32 = rotations.astype(np.float32), origins.astype(np.float32)
        normal_map = None
        if self.pose is None:
            orig, dirs = self._rays(rot32, orig32)
        else:  # the same rays in the mesh's own frame
            inv, shift, normal_map, diagonal = self.pose
            orig, dirs = self._rays(inv @ rot32, (orig32 - shift) @ inv.T)
        # embree writes each ray's hit distance into `dists`: inf stays where a ray misses
        dists = np.full(b * n, np.inf, np.float32)
        if normals:
            out = self.scene.run(orig, dirs, dists=dists, output=1)
            dist, normals = out["tfar"], out["Ng"]
        else:
            dist, normals = self.scene.run(orig, dirs, dists=dists, query="DISTANCE"), None
        if self.crop is not None:  # hits outside the box read as misses
            hit = np.flatnonzero(np.isfinite(dist))
            if self.pose is not None and diagonal is None:  # a turn: the world's own rays
                orig, dirs = self._rays(rot32, orig32)
            pts = orig[hit] + dirs[hit] * dist[hit, None]
            if self.pose is not None and diagonal is not None:  # back where the moved mesh is
                pts = pts * diagonal + shift
            outside = hit[~np.all((pts >= self.crop[0]) & (pts <= self.crop[1]), axis=1)]
            dist[outside] = np.inf
            if normals is not None:
                normals[outside] = 0
        return Hits(origins, rotations, dist.reshape(b, n),
                    None if normals is None else normals.reshape(b, n, 3), normal_map)

    def _rays(self, rot32, orig32):
        """(origins, directions) (B N, 3) float32 of every pixel's ray from poses (B, 3, 3), (B, 3)."""
        n = len(self.local_dirs)
        if len(orig32) == 1:  # the common case: one view per camera per step
            # (N, 3), a view of a (3, N) product into this thread's buffer (embree only reads it):
            # a fresh 48 KiB a cast faulted pages in, which two threads take in turn
            buf = getattr(_SCRATCH, "dirs", None)
            if buf is None or buf.shape[1] != n:
                buf = _SCRATCH.dirs = np.empty((3, n), np.float32)
            dirs = np.matmul(rot32[0], self._dirs32_t, out=buf).T
            # every ray starts at the camera: a read-only stride-0 view, no copy (embree only
            # reads it; a fresh one per call, so one camera may trace in two threads)
            orig = np.ndarray((n, 3), np.float32, orig32, 0, (0, orig32.itemsize))
            orig.flags.writeable = False
            return orig, dirs
        return np.repeat(orig32, n, 0), (rot32 @ self._dirs32_t).transpose(0, 2, 1).reshape(-1, 3)

    def zdepth(self, hits: Hits) -> np.ndarray:
        """Depth along the optical axis (B, H, W): D f / sqrt(x^2 + y^2 + f^2); inf on a miss."""
        return (hits.distance * self._cos32).reshape(-1, self.config.height, self.config.width)

    def render(self, views) -> np.ndarray:
        """Normalised depth (B, H, W) float32 in [0, 255], 255 = miss (the network's input)."""
        return self.render_hits(self.trace(views, normals=False))

    def render_hits(self, hits: Hits) -> np.ndarray:
        return self.normalise(self.zdepth(hits))

    def normalise(self, z):
        return normalise_depth(z, self.config)

    def metric(self, views) -> np.ndarray:
        """REP 118 depth in metres along the optical axis (B, H, W) float32, NaN = no return."""
        return self.metric_hits(self.trace(views, normals=False))

    def metric_hits(self, hits: Hits) -> np.ndarray:
        z = self.zdepth(hits)
        return np.where(np.isfinite(z), z, np.nan).astype(np.float32)

    def jacobian(self, hits: Hits, views, rule="paper") -> np.ndarray:
        """d(normalised depth)/d(theta, phi) per pixel, (B, N, 2); 0 on misses.

        paper: the hit point p stays fixed, d = f/sqrt(.) |X - p| - f  =>  dd/dX = cos (X - p)/D.
        surface: p slides on the tangent plane of its face; the ray (o + t w) keeps its pixel, so
        t = n.(p - o)/(n.w) and dt = -(n.do + t n.dw)/(n.w).
        """
        if rule not in GRADIENT_RULES:
            raise InputError(f"gradient rule must be one of {GRADIENT_RULES}, got {rule!r}")
        views = np.asarray(views, dtype=np.float64).reshape(-1, 2)
        d_rot = geometry.view_rotation_derivatives(views[:, 0], views[:, 1])  # (B, 2, 3, 3)
        d_orig = d_rot[..., 2] * self.config.radius                           # (B, 2, 3)
        rot = hits.rotations
        hit = hits.hit
        dist = np.where(hit, hits.distance, np.float32(0.0))                   # (B, N)
        # Pixels run along the last axis (3 x N blocks): every ray is w = R l for its t = 0
        # direction l, so all dot products become small per-view matrices times (3, N) blocks.
        if rule == "paper":
            # X - p = -D w, so dD/dX = (X - p)/D = -w and dD_k = -(R l).do_k = -(do_k R).l
            dD = -((d_orig @ rot).astype(np.float32) @ self._dirs32_t)         # (B, 2, N)
        else:
            n = np.ascontiguousarray(hits.world_normals().transpose(0, 2, 1))  # (B, 3, N)
            mats = np.concatenate([rot[:, None], d_rot], 1).reshape(-1, 9, 3)  # R, dR_theta, dR_phi
            w = (mats.astype(np.float32) @ self._dirs32_t).reshape(-1, 3, 3, n.shape[-1])
            proj = (w * n[:, None]).sum(2)                       # (B, 3, N): n.w, n.dw_theta, n.dw_phi
            nw = proj[:, 0]
            nw = np.where(np.abs(nw) < 1e-6, np.float32(1e-6), nw)
            n_do = d_orig.astype(np.float32) @ n                                # (B, 2, N)
            dD = -(n_do + dist[:, None] * proj[:, 1:]) / nw[:, None]
        near, far = self.config.depth_range
        z = dist * self._cos32
        inside = hit & (z > near) & (z < far)
        scale = np.where(inside, self._cos32 * np.float32(255.0 / (far - near)), np.float32(0.0))
        return (dD * scale[:, None]).transpose(0, 2, 1)                        # (B, N, 2)


def both_cores(fn, items):
    """[fn(x) for x in items] on both cores (embree casts without the GIL): this thread and the
    pool's take the next item from one shared counter, one hand-off a call (a future per item
    cost more than it gained). fn must not depend on which thread runs it."""
    items = list(items)
    if len(items) < 2:
        return [fn(x) for x in items]
    out = [None] * len(items)
    todo = iter(range(len(items)))  # next() on it is atomic under the GIL: each index once

    def work():
        for i in todo:
            out[i] = fn(items[i])

    helper = _POOL.submit(work)
    try:
        work()
    finally:
        helper.exception()  # waits: no item still running once this returns or raises
    helper.result()
    return out


def trace_all(cameras, views, normals=True):
    """Trace views[i] (2,) with cameras[i] on both cores: a list of one-view Hits (without the
    face normals where `normals` is False)."""
    views = np.asarray(views, dtype=np.float64).reshape(-1, 2)
    if len(cameras) != len(views):
        raise InputError(f"{len(cameras)} cameras for {len(views)} views")
    return both_cores(lambda cv: cv[0].trace(cv[1], normals), zip(cameras, views))


def render_batch(cameras, views):
    """Normalised depth (sum of B_i, H, W) of cameras[i] rendered at views[i] ((B_i, 2) each, or
    one (B, 2) set for all): cast on both cores, normalised in one pass."""
    if len(views) and np.ndim(views[0]) == 1:
        views = [views] * len(cameras)
    return render_all(cameras, both_cores(lambda cv: cv[0].trace(cv[1], normals=False), zip(cameras, views)))


def render_all(cameras, hits):
    """Normalised depth of each camera's hits, concatenated: in one pass where the cameras share
    their table (the casting threads then hold the GIL only to set up their rays)."""
    if not shared_table(cameras):
        return np.concatenate([c.render_hits(h) for c, h in zip(cameras, hits)])
    return cameras[0].render_hits(Hits(None, None, np.concatenate([h.distance for h in hits]), None))


def shared_table(cameras):
    """Whether these are DepthCameras of one config and pixel table, so their depths normalise
    in one pass (elementwise: bit for bit the same as one camera at a time)."""
    first = cameras[0] if len(cameras) else None
    return first is not None and all(type(c) is DepthCamera and c.config == first.config
                                     and c._cos32 is first._cos32 for c in cameras)


class _RenderViews(torch.autograd.Function):
    @staticmethod
    def forward(ctx, views, cameras, rule, reduction):
        v = views.detach().cpu().numpy().astype(np.float64)
        hits = trace_all(cameras, v, normals=rule == "surface")  # only that rule reads them
        depth = render_all(cameras, hits)
        ctx.cameras, ctx.hits, ctx.views, ctx.rule, ctx.reduction = cameras, hits, v, rule, reduction
        return torch.from_numpy(depth).to(views.device)

    @staticmethod
    def backward(ctx, grad):
        g = grad.detach().cpu().numpy().reshape(len(grad), -1).astype(np.float32)

        def view_grad(i):
            jac = ctx.cameras[i].jacobian(ctx.hits[i], ctx.views[i], ctx.rule)[0]   # (N, 2)
            total = g[i] @ jac                           # sum over pixels of dL/dd * dd/dview
            return total / len(jac) if ctx.reduction == "mean" else total

        # sequential: BLAS from pool threads beside torch's own backward aborted a DDP worker once
        out = np.stack([view_grad(i) for i in range(len(g))])
        return torch.from_numpy(out).to(grad.device, grad.dtype), None, None, None


def render_views(views: torch.Tensor, cameras, rule="paper", reduction="mean") -> torch.Tensor:
    """Differentiable render: views (B, 2) -> normalised depth (B, H, W), one camera per row.

    The backward turns dloss/d(depth) into dloss/d(view) with `rule` ("paper" or "surface"),
    reducing the per-pixel terms by "mean" (the paper) or "sum".
    """
    if rule not in GRADIENT_RULES:
        raise InputError(f"gradient rule must be one of {GRADIENT_RULES}, got {rule!r}")
    if reduction not in ("mean", "sum"):
        raise InputError(f"gradient reduction must be 'mean' or 'sum', got {reduction!r}")
    if views.ndim != 2 or views.shape[1] != 2:
        raise InputError(f"views must be (B, 2) (theta, phi), got {tuple(views.shape)}")
    return _RenderViews.apply(views, list(cameras), rule, reduction)
