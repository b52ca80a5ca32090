# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""The generated unknown objects: valid closed parts for every kind and style, disjoint styles per
split, determinism in the seed, and the dataset's own validation split."""
import importlib
import itertools

import numpy as np
import pytest
import trimesh

from active_recognition.argument_checks import InputError
from active_recognition.datasets import near, open_splits
from active_recognition.datasets.parts import Style
from active_recognition.datasets.unknowns import (FACTORS, GENERATORS, KINDS, SPLITS, make_unknown, styles,
                                                  unknowns)

unknowns_module = importlib.import_module("active_recognition.datasets.unknowns")  # the package names a function so


@pytest.mark.parametrize("kinds, name", [(unknowns_module, k) for k in KINDS] + [(near, k) for k in near.KINDS])
def test_every_style_builds_closed_parts(kinds, name):
    """Generated unknowns and near unknowns (datasets/near.py) alike; the near ones on the floor."""
    na, nb = kinds.FACTORS[name]
    for a, b in itertools.product(range(na), range(nb)):
        rng = np.random.default_rng([a, b])
        parts = kinds.GENERATORS[name](rng, a, b, Style.draw(rng))
        assert parts, (name, a, b)
        for p in parts:  # each part closed and of positive volume: the whole is watertight-ish
            assert p.is_watertight and p.volume > 0, (name, a, b)
        if kinds is near:  # furniture stands on z = 0: only a shelf's cross brace (3 cm wide, corner
            # to corner) reaches below, by at most half its width
            assert -0.015 - 1e-6 <= trimesh.util.concatenate(parts).bounds[0, 2] <= 1e-6, (name, a, b)


@pytest.mark.parametrize("label", range(len(KINDS)))
def test_shapes_are_normalised_and_not_flat(label):
    v, f, size = make_unknown(label, 7, "test")
    assert v.dtype == np.float32 and f.dtype == np.int32 and f.max() < len(v)
    assert np.abs(v).max() <= 0.5 + 1e-6 and np.isclose(np.ptp(v, 0).max(), 1.0, atol=1e-5)
    mesh = trimesh.Trimesh(v, f, process=False)
    assert mesh.area > 0 and (np.ptp(v, 0) > 0.02).all()


def test_sizes_are_the_built_boxes_in_metres(tmp_path):
    """Each unknown's size is its box as built (rebuilt here from the same seed and style, with
    the generator itself), kept through the cache; a cup is small, an airplane large."""
    ds = unknowns("val", cache_dir=tmp_path, per_class=2)
    for i, (source, label) in enumerate(ds.items):
        rng = np.random.default_rng(int(source.split("/")[1]))
        options = styles(KINDS[label], "val")
        pick = options[int(rng.random() * len(options))]
        built = trimesh.util.concatenate(GENERATORS[KINDS[label]](rng, *pick, Style.draw(rng)))
        assert ds.size(i) == pytest.approx(np.ptp(built.vertices, 0).max(), rel=1e-9)
    again = unknowns("val", cache_dir=tmp_path, per_class=2)  # read back from the cache
    assert [again.size(i) for i in range(len(again))] == [ds.size(i) for i in range(len(ds))]
    by_kind = {KINDS[label]: ds.size(i) for i, (_, label) in enumerate(ds.items)}
    assert by_kind["cup"] < 0.3 < 2.0 < by_kind["airplane"]


def test_splits_have_disjoint_nonempty_styles():
    for name in KINDS:
        got = {s: set(styles(name, s)) for s in SPLITS}
        assert all(got.values())
        assert not got["val"] & got["test"] and not got["train"] & (got["val"] | got["test"])
        assert set.union(*got.values()) == set(itertools.product(*map(range, FACTORS[name])))


def test_styles_differ_between_kinds_and_are_seeded():
    assert len({tuple(styles(n, "test")) for n in KINDS}) > 1  # dealt per kind, not one pattern
    assert styles("lamp", "val") == styles("lamp", "val")


def test_seeded_determinism_and_splits_apart():
    a, b = unknowns("val", per_class=2), unknowns("val", per_class=2)
    for i in range(len(a)):
        assert all(np.array_equal(x, y) for x, y in zip(a.mesh(i), b.mesh(i)))
    other = unknowns("val", per_class=2, seed=1)
    assert not np.array_equal(a.mesh(0)[0], other.mesh(0)[0])
    test = unknowns("test", per_class=2)
    assert {s for s, _ in a.items}.isdisjoint(s for s, _ in test.items)
    assert list(a.labels()) == [k for k in range(len(KINDS)) for _ in range(2)]


def test_open_splits_keeps_its_own_validation_split(tmp_path):
    parts = open_splits("unknowns", None, ("train", "val", "test"), tmp_path, per_class=1)
    assert [len(parts[s]) for s in SPLITS] == [len(KINDS)] * 3
    assert parts["val"].split == "val" and (tmp_path / "unknowns").is_dir()
    again = open_splits("unknowns", None, ("val",), tmp_path, per_class=1)["val"]  # from the cache
    assert np.array_equal(again.mesh(3)[0], parts["val"].mesh(3)[0])


def test_bad_split_and_kind_are_refused():
    with pytest.raises(InputError, match="split of unknowns"):
        unknowns("cross")
    with pytest.raises(InputError, match="kind"):
        styles("toaster", "val")
