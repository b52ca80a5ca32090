# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""Depth layer speed: the same rays three ways on a ~20k-face mesh, at 64x64 and 227x227.

ours     -- DepthCamera.render (ray set-up, embree, hit table, normalised depth)
embreex  -- raw EmbreeScene.run(output=1) on the precomputed rays (distances + normals, as we need)
trimesh  -- trimesh's RayMeshIntersector.intersects_location on the same rays, then the depth
Also a batch of 32 renders (32 cameras around 32 different shapes, a view each, as a training
step renders them) with one thread vs both cores, timed in turn (`two_thread_speedup`); the same
with one shape's camera 32 times (`_one_shape`: its scene stays hot in the cache); and the 32
traced with face normals. Medians; last line
is JSON.
"""
import numpy as np
import trimesh
from common import emit, median_ms, paired_median_ms
from embreex import rtcore_scene
from embreex.mesh_construction import TriangleMesh

from active_recognition.sensing import geometry
from active_recognition.sensing.depth_layer import CameraConfig, DepthCamera, _DEVICE, render_batch, trace_all
from active_recognition.sensing.meshes import normalise
from active_recognition.training.devices import keep_freed_memory


def rays(cam, view):
    rot = geometry.view_rotation(*view)
    dirs = (cam.local_dirs @ rot.T).astype(np.float32)
    orig = np.repeat(geometry.camera_position(*view, cam.config.radius)[None].astype(np.float32),
                     len(dirs), 0)
    return orig, dirs


def main():
    keep_freed_memory()  # as training does
    # 20,480 faces, normalised into [-0.5, 0.5]^3 like every dataset mesh the camera sees
    mesh = trimesh.creation.icosphere(subdivisions=5, radius=1.0)
    mesh.vertices = normalise(mesh.vertices * [1.0, 0.7, 0.55])
    view = (1.1, 0.4)
    out = {"faces": len(mesh.faces)}
    for size in (64, 227):
        cam = DepthCamera.from_mesh(mesh, CameraConfig(size, size))
        o, d = rays(cam, view)
        scene = rtcore_scene.EmbreeScene(_DEVICE)
        TriangleMesh(scene, mesh.vertices.astype(np.float32), mesh.faces.astype(np.int32))
        intersector = trimesh.ray.ray_pyembree.RayMeshIntersector(mesh)

        def via_trimesh():
            loc, idx, _ = intersector.intersects_location(o, d, multiple_hits=False)
            dist = np.full(len(o), np.inf)
            dist[idx] = np.linalg.norm(loc - o[idx], axis=1)
            return cam.normalise(dist * cam.cos)

        np.testing.assert_allclose(via_trimesh(), cam.render(view)[0].ravel(), atol=0.05)
        ours = median_ms(lambda: cam.render(view), repeat=300)
        raw = median_ms(lambda: scene.run(o, d, output=1), repeat=300)
        tri = median_ms(via_trimesh, repeat=100)
        out[f"ms_per_image_{size}"] = ours
        out[f"raw_embreex_ms_{size}"] = raw
        out[f"trimesh_ms_{size}"] = tri
        out[f"ratio_vs_embreex_{size}"] = ours / raw
        out[f"speedup_vs_trimesh_{size}"] = tri / ours
        print(f"{size}x{size}: ours {ours:.3f} ms, raw embreex {raw:.3f} ms, trimesh {tri:.3f} ms")
    out["mrays_per_s"] = 64 * 64 / (out["ms_per_image_64"] * 1e-3) / 1e6
    # a training step's render: 32 different objects, each camera at its one view, distances
    # only, normalised; each scene cold in the cache as in training (32 copies of one scene keep
    # its tree hot, each cast shorter, so the fixed hand-off of the helper thread weighs more)
    rng = np.random.default_rng(0)
    shapes = [DepthCamera(normalise(mesh.vertices * rng.uniform(0.4, 1.0, 3)), mesh.faces,
                          CameraConfig(64, 64)) for _ in range(32)]
    views = np.tile(np.array(view), (32, 1, 1))
    for key, cams in (("", shapes), ("_one_shape", [DepthCamera.from_mesh(mesh, CameraConfig(64, 64))] * 32)):
        one, two = paired_median_ms([lambda: np.concatenate([c.render(v) for c, v in zip(cams, views)]),
                                     lambda: render_batch(cams, views)], repeat=200)
        out[f"batch32{key}_one_thread_ms"], out[f"batch32{key}_two_threads_ms"] = one, two
        out[f"two_thread_speedup{key}"] = one / two
        print(f"batch of 32 renders{key.replace('_', ' ')}: one thread {one:.1f} ms, two threads {two:.1f} ms")
    cams = shapes
    one, two = paired_median_ms([lambda: [c.trace(v) for c, v in zip(cams, views)],
                                 lambda: trace_all(cams, views[:, 0])], repeat=200)
    out["traced_with_normals_speedup"] = one / two  # the hit tables the surface rule reads
    print(f"the same 32 traced with face normals: one thread {one:.1f} ms, two threads {two:.1f} ms")
    emit(out)


if __name__ == "__main__":
    main()
