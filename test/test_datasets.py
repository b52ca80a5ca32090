# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""Datasets: the generated ones (procedural, twins), the file layouts (ModelNet, ShapeNet, folder)
on small generated trees, their splits, caches and refusals."""
import json

import numpy as np
import pytest
import trimesh

from active_recognition.argument_checks import InputError
from active_recognition.datasets import open_dataset, procedural
from active_recognition.datasets.furniture import FACTORS, styles
from active_recognition.datasets.parts import Style, leg, place, slab
from active_recognition.datasets.procedural import CLASSES, make_shape
from active_recognition.sensing.depth_layer import CameraConfig, DepthCamera
from active_recognition.sensing.meshes import MeshError, load_mesh

CUBE_V = [(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0), (0, 0, 1), (1, 0, 1), (1, 1, 1), (0, 1, 1)]
CUBE_QUADS = [(0, 3, 2, 1), (4, 5, 6, 7), (0, 1, 5, 4), (1, 2, 6, 5), (2, 3, 7, 6), (3, 0, 4, 7)]
PLY_HEADER = ("ply\nformat ascii 1.0\nelement vertex {}\nproperty float x\nproperty float y\n"
              "property float z\nelement face {}\nproperty list uchar int vertex_indices\n"
              "end_header\n")


def write_off(path, verts, faces, fused=False):
    head = f"OFF{len(verts)} {len(faces)} 0\n" if fused else f"OFF\n{len(verts)} {len(faces)} 0\n"
    body = "".join(f"{x} {y} {z}\n" for x, y, z in verts)
    body += "".join(f"{len(f)} {' '.join(map(str, f))}\n" for f in faces)
    path.write_text(head + body)
    return path


def test_fused_header_and_quads_are_triangulated(tmp_path):
    v, f = load_mesh(write_off(tmp_path / "a.off", CUBE_V, CUBE_QUADS, fused=True))
    assert f.shape == (12, 3) and v.shape == (8, 3)
    mesh = trimesh.Trimesh(v, f)
    assert mesh.is_watertight and abs(mesh.area - 6.0) < 1e-6  # unit cube, quads split in two


def test_offset_and_scaled_mesh_is_normalised(tmp_path):
    far = np.array(CUBE_V, float) * [1650, 300, 20] + [5000, -1200, 77]
    v, _ = load_mesh(write_off(tmp_path / "far.off", far, CUBE_QUADS))
    np.testing.assert_allclose(v.min(0), [-0.5, -300 / 3300, -20 / 3300], atol=1e-6)
    np.testing.assert_allclose(v.max(0), [0.5, 300 / 3300, 20 / 3300], atol=1e-6)
    m = trimesh.creation.icosphere(2, radius=40.0)
    m.apply_translation([100, 200, 300])
    for ext in ("obj", "ply", "stl", "glb"):
        m.export(tmp_path / f"s.{ext}")
        v, f = load_mesh(tmp_path / f"s.{ext}")
        np.testing.assert_allclose(v.max(0) - v.min(0), [1, 1, 1], atol=1e-5)
        np.testing.assert_allclose(v.max(0) + v.min(0), 0, atol=1e-5)


@pytest.mark.parametrize("name,content,reason", [
    ("empty.off", "", "empty"),
    ("trunc.off", "OFF\n8 6 0\n0 0 0\n1 0 0\n", "truncated"),
    ("garbage.off", "\x00\x01hello", "OFF"),
    ("garbage.obj", "this is not a mesh at all", "fewer than 3 vertices"),
    ("lie.off", "OFF\n3 1000 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n",
     "declares 1000 faces but the file holds 1"),
    ("lie.ply", PLY_HEADER.format(3, 1000) + "0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n",
     "declares 3 vertices and 1000 faces, the file holds 3 and 1"),
    ("fewverts.ply", PLY_HEADER.format(300, 1) + "0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n",
     "declares 300 vertices"),
    ("flat.off", "OFF\n3 1 0\n0 0 0\n0 0 0\n0 0 0\n3 0 1 2\n", "zero"),
    ("mesh.txt", "whatever", "unsupported"),
])
def test_bad_files_raise_one_clear_error(tmp_path, name, content, reason):
    path = tmp_path / name
    path.write_text(content)
    with pytest.raises(MeshError) as e:
        load_mesh(path)
    assert name in str(e.value) and reason.lower() in str(e.value).lower()


@pytest.mark.parametrize("suffix,reason", [
    (".obj", "not a text OBJ file"), (".off", "not a text OFF file"),
    (".ply", "not a PLY file (no 'ply' signature)"), (".glb", "not a GLB file"),
    (".stl", "not an STL file")])
def test_random_bytes_give_a_message_about_the_file(tmp_path, suffix, reason):
    path = tmp_path / f"noise{suffix}"
    path.write_bytes(np.random.default_rng(7).integers(0, 256, 3000, dtype=np.uint8).tobytes())
    with pytest.raises(MeshError) as e:
        load_mesh(path)
    assert str(e.value) == f"{path}: {e.value.reason}" and reason in e.value.reason
    assert "module" not in str(e.value)


def test_a_ply_of_quads_declares_fewer_faces_than_its_triangles_and_loads(tmp_path):
    body = "".join(f"{x} {y} {z}\n" for x, y, z in CUBE_V)
    body += "".join(f"4 {' '.join(map(str, q))}\n" for q in CUBE_QUADS)
    (tmp_path / "cube.ply").write_text(PLY_HEADER.format(8, 6) + body)
    v, f = load_mesh(tmp_path / "cube.ply")
    assert f.shape == (12, 3) and abs(trimesh.Trimesh(v, f).area - 6.0) < 1e-6


def test_a_folder_named_like_a_mesh_is_named_as_a_folder(tmp_path):
    (tmp_path / "dir.obj").mkdir()
    with pytest.raises(MeshError, match="dir.obj: is a directory, not a file"):
        load_mesh(tmp_path / "dir.obj")


def test_modelnet_tree_with_a_bad_file(tmp_path):
    for c in ("chair", "table"):
        for split, n in (("train", 3), ("test", 1)):
            d = tmp_path / c / split
            d.mkdir(parents=True)
            for i in range(n):
                write_off(d / f"{c}_{i}.off", np.array(CUBE_V) * (i + 1), CUBE_QUADS, fused=i == 0)
    (tmp_path / "table" / "train" / "table_bad.off").write_text("OFF\n8 6 0\n1 2")
    train = open_dataset("modelnet", tmp_path, "train", cache_dir=tmp_path / "cache")
    test = open_dataset("modelnet", tmp_path, "test")
    assert train.classes == ["chair", "table"] and list(train.class_counts()) == [3, 3]
    assert list(test.class_counts()) == [1, 1]
    assert len(train.skipped) == 1 and train.skipped[0][0].endswith("table_bad.off")
    # a second open reads the cache, with the same arrays
    again = open_dataset("modelnet", tmp_path, "train", cache_dir=tmp_path / "cache")
    assert len(list((tmp_path / "cache" / "meshes").glob("*.npz"))) == 7  # 6 + the bad one's reason
    for i in range(len(again)):
        np.testing.assert_array_equal(again.mesh(i)[0], train.mesh(i)[0])


def test_a_class_in_one_split_only_keeps_its_label_and_counts_zero_in_the_other(tmp_path):
    for c, splits in (("chair", ("train", "test")), ("lamp", ("test",)), ("table", ("train", "test"))):
        for split in splits:
            (tmp_path / c / split).mkdir(parents=True)
            write_off(tmp_path / c / split / f"{c}.off", CUBE_V, CUBE_QUADS)
    train, test = (open_dataset("modelnet", tmp_path, s, cache_dir=str(tmp_path / "c"))
                   for s in ("train", "test"))
    assert train.classes == test.classes == ["chair", "lamp", "table"]
    assert list(train.class_counts()) == [1, 0, 1] and list(test.class_counts()) == [1, 1, 1]
    for p, label in test.items:  # each object under its own folder's class
        assert test.classes[label] == p.parent.parent.name
    assert len(list((tmp_path / "c" / "meshes").glob("*.npz"))) == 5  # a str cache_dir works


def test_a_layout_that_finds_no_objects_says_what_it_looked_for(tmp_path):
    (tmp_path / "chair" / "train").mkdir(parents=True)
    write_off(tmp_path / "chair" / "train" / "a.off", CUBE_V, CUBE_QUADS)
    ds = open_dataset("folder", tmp_path, "train")
    assert len(ds) == 0
    with pytest.raises(InputError, match=r"no train objects found in folder root .*<class>/\*"
                                         r".*look like modelnet's: --name modelnet\?"):
        ds.require_objects()
    assert open_dataset("modelnet", tmp_path, "train").require_objects().classes == ["chair"]


def test_a_damaged_generated_cache_is_rebuilt_not_trusted(tmp_path):
    ds = procedural("test", cache_dir=tmp_path, per_class=2)
    (cached,) = (tmp_path / "procedural").glob("*.npz")
    cached.write_bytes(cached.read_bytes()[:100])  # a half-written file
    again = procedural("test", cache_dir=tmp_path, per_class=2)
    for i in range(len(ds)):
        np.testing.assert_array_equal(again.mesh(i)[0], ds.mesh(i)[0])
    assert procedural("test", cache_dir=tmp_path, per_class=2).mesh(3)[1].shape == ds.mesh(3)[1].shape


def test_shapenet_tree_uses_taxonomy_and_a_stable_split(tmp_path):
    box = trimesh.creation.box()
    for synset in ("03001627", "04379243"):
        for i in range(10):
            d = tmp_path / synset / f"model{i:02d}" / "models"
            d.mkdir(parents=True)
            box.export(d / "model_normalized.obj")
    (tmp_path / "taxonomy.json").write_text(json.dumps(
        [{"synsetId": "03001627", "name": "chair,seat"}, {"synsetId": "04379243", "name": "table"}]))
    train, val, test = (open_dataset("shapenet", tmp_path, s) for s in ("train", "val", "test"))
    assert train.classes == ["chair", "table"]
    assert len(train) + len(val) + len(test) == 20 and len(test) > 0
    assert not {str(p) for p, _ in train.items + val.items} & {str(p) for p, _ in test.items}
    again = open_dataset("shapenet", tmp_path, "test")
    assert [str(p) for p, _ in again.items] == [str(p) for p, _ in test.items]


def test_folder_layout(tmp_path):
    for c in ("a", "b"):
        (tmp_path / c).mkdir()
        for i in range(6):
            trimesh.creation.box(extents=(1, i + 1, 1)).export(tmp_path / c / f"{i}.stl")
        (tmp_path / c / "notes.txt").write_text("not a mesh")
    train, val, test = (open_dataset("folder", tmp_path, s) for s in ("train", "val", "test"))
    assert train.classes == ["a", "b"] and len(train) + len(val) + len(test) == 12


def test_unknown_dataset_and_missing_root_are_clear_errors(tmp_path):
    with pytest.raises(InputError, match="dataset must be one of .*, got 'imagenet'"):
        open_dataset("imagenet")
    with pytest.raises(InputError, match="nope: no such directory"):
        open_dataset("modelnet", tmp_path / "nope")
    with pytest.raises(InputError, match=r"needs its root folder \(--root DIR; a node's parameter root\)"):
        open_dataset("modelnet")
    (tmp_path / "file").write_text("x")
    with pytest.raises(InputError, match="file: is not a directory"):
        open_dataset("folder", tmp_path / "file")
    with pytest.raises(InputError, match="procedural dataset is generated: it takes no root"):
        open_dataset("procedural", tmp_path)


def test_procedural_is_deterministic_and_seeds_differ():
    a, b = make_shape(3, 42), make_shape(3, 42)
    np.testing.assert_array_equal(a[0], b[0])
    c = make_shape(3, 43)
    assert a[0].shape != c[0].shape or not np.allclose(a[0], c[0])


@pytest.mark.parametrize("label", range(len(CLASSES)))
def test_procedural_styles_render_with_hits_from_every_side(label):
    cfg = CameraConfig(32, 32)
    views = np.array([[0.2, 0.0], [1.57, 0.0], [1.57, 1.57], [2.9, 0.0]])
    for style in styles(CLASSES[label]) + styles(CLASSES[label], held_out=True):
        for seed in range(2):
            v, f = make_shape(label, seed, style=style)
            assert np.all(v >= -0.5 - 1e-6) and np.all(v <= 0.5 + 1e-6)
            assert np.isclose((v.max(0) - v.min(0)).max(), 1.0, atol=1e-6)
            depth = DepthCamera(v, f, cfg).render(views)
            assert np.all((depth < 255).sum(axis=(1, 2)) >= 5), CLASSES[label]  # a side-on monitor is thin


def test_procedural_split_cache_round_trips(tmp_path):
    ds = procedural("test", cache_dir=tmp_path, per_class=2)
    assert len(ds) == 20 and list(ds.class_counts()) == [2] * 10
    again = procedural("test", cache_dir=tmp_path, per_class=2)
    for i in range(20):
        np.testing.assert_array_equal(ds.mesh(i)[1], again.mesh(i)[1])
    train = procedural("train", per_class=2)
    assert not {p for p, _ in train.items} & {p for p, _ in ds.items}


def drawn_style(ds, i):
    """The style a generated item was built in: the one whose forced build matches it (the
    style draw is made either way, so the rest of the draws agree)."""
    label, seed = ds.items[i][1], int(ds.items[i][0].split("/")[1])
    na, nb = FACTORS[CLASSES[label]]
    v = ds.mesh(i)[0]
    found = [(a, b) for a in range(na) for b in range(nb)
             if np.array_equal(make_shape(label, seed, style=(a, b))[0], v)]
    assert len(found) == 1, found
    return label, found[0]


@pytest.mark.slow
def test_the_cross_style_split_holds_only_the_held_out_combinations():
    train, cross = (open_dataset("procedural", split=s, per_class=4) for s in ("train", "cross"))
    for ds, held_out in ((train, False), (cross, True)):
        for i in range(len(ds)):
            label, style = drawn_style(ds, i)
            assert style in styles(CLASSES[label], held_out)
    assert list(cross.class_counts()) == [4] * len(cross.classes)
    assert not {p for p, _ in train.items} & {p for p, _ in cross.items}


@pytest.mark.parametrize("name", CLASSES)
def test_every_option_of_every_factor_is_trained_on(name):
    train, held = styles(name), styles(name, held_out=True)
    na, nb = FACTORS[name]
    assert held and not set(train) & set(held) and len(train) + len(held) == na * nb
    assert {a for a, _ in train} == set(range(na)) and {b for _, b in train} == set(range(nb))


@pytest.mark.parametrize("edge", ["bevel", "round"])
@pytest.mark.parametrize("axis", [0, 1, 2])
def test_a_slab_with_soft_edges_fills_its_box_less_a_corner_strip(edge, axis):
    size = np.array([0.5, 0.3, 0.2])
    m = slab((1, 2, 3), size, Style(edge=edge, quad_segs=4), axis=axis, radius=0.05)
    np.testing.assert_allclose(m.bounds, [np.array((1, 2, 3)) - size / 2, np.array((1, 2, 3)) + size / 2],
                               atol=1e-9)
    assert m.is_watertight and m.volume > 0  # `place` rotates, never mirrors
    # four corners of r = 0.05 cut off along the axis: r^2 (4 - pi) for round, r^2 * 2 for bevel
    lost = 0.05 ** 2 * ((4 - np.pi) if edge == "round" else 2.0) * size[axis]
    assert abs((size.prod() - m.volume) - lost) < 0.12 * lost


@pytest.mark.parametrize("kind", ["square", "round", "tapered", "turned", "splayed"])
def test_every_leg_stands_on_the_floor_and_reaches_its_height(kind):
    m = leg(kind, (0.3, -0.2), 0.7, 0.05, Style(sections=12), outward=(1, -1))
    assert abs(m.bounds[1, 2] - 0.7) < 0.01 and m.bounds[0, 2] > -0.01
    assert m.volume > 0 and np.hypot(*(m.center_mass[:2] - (0.3, -0.2))) < 0.08
    top = m.vertices[m.vertices[:, 2] > 0.69]
    np.testing.assert_allclose(top[:, :2].mean(0), (0.3, -0.2), atol=0.02)
    assert place(leg(kind, (0, 0), 1, 0.1, Style()), (0, 0, 0), axis=0).volume > 0


def test_the_validation_split_is_a_seeded_tenth_of_each_class_of_train(tmp_path):
    from active_recognition.datasets import validation_split
    from active_recognition.datasets.modelnet import modelnet

    for c, n in (("chair", 30), ("desk", 14), ("lamp", 4)):
        (tmp_path / c / "train").mkdir(parents=True)
        for i in range(n):
            write_off(tmp_path / c / "train" / f"{c}_{i:02d}.off", np.array(CUBE_V) * (1 + i / n),
                      CUBE_QUADS)
    val = open_dataset("modelnet", tmp_path, "val", cache_dir=tmp_path / "c")
    train = open_dataset("modelnet", tmp_path, "train", cache_dir=tmp_path / "c")
    assert (val.split, train.split) == ("val", "train")
    assert list(val.class_counts()) == [3, 1, 0]  # round(10 %): 3 of 30, 1 of 14, none of 4
    assert list(train.class_counts()) == [27, 13, 4]
    names = {s: {str(p) for p, _ in ds.items} for s, ds in (("val", val), ("train", train))}
    assert not names["val"] & names["train"]
    whole = {str(p) for p, _ in modelnet(tmp_path, "train").items}  # the official split
    assert names["val"] | names["train"] == whole and len(whole) == 48
    again = open_dataset("modelnet", tmp_path, "val", cache_dir=tmp_path / "c")
    assert [str(p) for p, _ in again.items] == [str(p) for p, _ in val.items]  # seeded
    other = validation_split(modelnet(tmp_path, "train"), "val", seed=1)
    assert {str(p) for p, _ in other.items} != names["val"]
    for p, label in val.items:  # labels follow the files
        assert val.classes[label] == p.parent.parent.name


def test_generated_benchmarks_have_a_validation_split_and_file_ones_no_cross(tmp_path):
    val = open_dataset("procedural", split="val", cache_dir=tmp_path, per_class=20)
    train = open_dataset("procedural", split="train", cache_dir=tmp_path, per_class=20)
    assert set(val.class_counts()) == {2} and set(train.class_counts()) == {18}
    with pytest.raises(InputError, match="split must be one of train, val, test, cross, got 'dev'"):
        open_dataset("procedural", split="dev", cache_dir=tmp_path)
    (tmp_path / "m" / "chair" / "test").mkdir(parents=True)
    with pytest.raises(InputError, match="the cross split .* modelnet has train, val and test"):
        open_dataset("modelnet", tmp_path / "m", "cross")


@pytest.mark.parametrize("per_class, held", [(5, 0), (6, 1)])
def test_a_validation_split_too_small_to_hold_anything_is_said(tmp_path, per_class, held):
    """A tenth of each class, rounded: 5 objects give none (and a warning), 6 give one."""
    import warnings
    with warnings.catch_warnings(record=True) as said:
        warnings.simplefilter("always")
        val = open_dataset("procedural", split="val", cache_dir=tmp_path, per_class=per_class)
    assert set(val.class_counts()) == {held}
    assert [str(w.message) for w in said if "validation split is empty" in str(w.message)] == (
        [] if held else ["procedural: the validation split is empty (a tenth of each class of train, rounded: no "
                         "class has 6 objects): training reports no per-epoch figures, and nothing can be chosen "
                         "on it"])


def test_shapes_with_a_yaw_turn_each_object_by_its_own_seeded_yaw_within_the_bound():
    """Shapes(yaw=30): each camera holds the dataset's mesh turned by its own yaw (meshes.yawed),
    every yaw within +-30 degrees, the same for the same seed and another for another; the
    shared classifier's fingerprint tells the turned shapes from the upright ones."""
    from active_recognition.datasets.shapes import Shapes
    from active_recognition.evaluation.shared_classifier import fingerprint
    from active_recognition.sensing.meshes import yawed
    ds = open_dataset("twins", split="test", per_class=2)
    cam = CameraConfig(32, 32)
    upright, turned, again, other = (Shapes(ds, cam, yaw, seed) for yaw, seed in
                                     ((0, 0), (30, 0), (30, 0), (30, 1)))
    assert upright.yaws is None
    assert np.abs(np.degrees(turned.yaws)).max() <= 30 and np.ptp(turned.yaws) > np.radians(20)
    np.testing.assert_array_equal(turned.yaws, again.yaws)
    assert not np.allclose(turned.yaws, other.yaws)
    for i in (0, 5, len(ds) - 1):
        v, f = ds.mesh(i)
        np.testing.assert_array_equal(upright.mesh(i)[0], v)
        np.testing.assert_allclose(turned.mesh(i)[0], yawed(v, turned.yaws[i]))
        view = np.array([[1.2, 0.4]])
        np.testing.assert_array_equal(turned.cameras([i])[0].render(view),
                                      DepthCamera(yawed(v, turned.yaws[i]), f, cam).render(view))
    assert fingerprint(turned) != fingerprint(upright) == fingerprint(Shapes(ds, cam))


@pytest.mark.slow
def test_a_simulated_camera_opens_a_split_once_for_every_object_it_shows(tmp_path, monkeypatch,
                                                                         dataset_cache):
    """Switching objects reads the split's index once per process and cache folder; another
    cache folder opens it again; the meshes are the dataset's own."""
    import shutil

    import active_recognition.simulation.depth_sensor as sc
    opened = []
    real = sc.open_dataset
    monkeypatch.setattr(sc, "open_dataset", lambda *a, **k: opened.append(a) or real(*a, **k))
    sc.opened.cache_clear()
    monkeypatch.setenv("ACTIVE_RECOGNITION_CACHE", str(dataset_cache))
    shown = [sc.load_object(dataset="twins", split="test", index=i) for i in (0, 3, 0)]
    assert len(opened) == 1 and shown[0][2] == shown[2][2] != shown[1][2]
    ds = open_dataset("twins", split="test")  # built afresh, without a cache
    np.testing.assert_array_equal(shown[1][0], ds.mesh(3)[0])
    # another folder holding the same cache file (copied: building the split again costs seconds)
    shutil.copytree(dataset_cache / "twins", tmp_path / "b" / "twins")
    monkeypatch.setenv("ACTIVE_RECOGNITION_CACHE", str(tmp_path / "b"))
    sc.load_object(dataset="twins", split="test", index=1)
    assert len(opened) == 2
    sc.opened.cache_clear()


def test_a_subset_of_max_shapes_holds_every_class_and_is_the_plain_draw_where_that_does():
    from active_recognition.datasets import subset_with_every_class
    labels = np.array([0] * 90 + [1] * 5 + [2] * 5)  # a plain draw of 4 misses classes for most seeds
    for seed in range(20):
        got = subset_with_every_class(labels, 4, seed)
        assert len(got) == 4 and set(labels[got]) == {0, 1, 2} and list(got) == sorted(set(got))
        np.testing.assert_array_equal(got, subset_with_every_class(labels, 4, seed))  # seeded
        plain = np.sort(np.random.default_rng(seed).permutation(100)[:40])
        if set(labels[plain]) == {0, 1, 2}:  # where the plain draw holds every class, it is kept
            np.testing.assert_array_equal(subset_with_every_class(labels, 40, seed), plain)
    assert len(subset_with_every_class(labels, 1000, 0)) == 100
    with pytest.raises(InputError, match="max_shapes = 2 cannot hold an object of each of the 3 classes"):
        subset_with_every_class(labels, 2, 0)
