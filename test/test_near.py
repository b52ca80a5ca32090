# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""The generated near unknowns (furniture-like objects of no ModelNet10 class): normalised meshes,
sizes in metres as built, determinism in the seed (their parts: test_unknowns.py)."""
import numpy as np
import pytest

from active_recognition.argument_checks import InputError
from active_recognition.datasets.near import KINDS, make_near, near_unknowns


@pytest.mark.parametrize("label", range(len(KINDS)))
def test_shapes_are_normalised_seeded_and_of_their_kinds_size(label):
    v, f, size = make_near(label, 11)
    assert v.dtype == np.float32 and f.dtype == np.int32 and f.max() < len(v)
    assert np.abs(v).max() <= 0.5 + 1e-6 and np.isclose(np.ptp(v, 0).max(), 1.0, atol=1e-5)
    again = make_near(label, 11)
    assert np.array_equal(v, again[0]) and size == again[2]
    assert not np.array_equal(v, make_near(label, 12)[0]) or len(v) != len(make_near(label, 12)[0])
    lo, hi = {"stool": (0.3, 0.9), "shelf": (0.5, 2.1), "cabinet": (0.6, 2.7), "appliance": (0.4, 1.95),
              "piano": (1.3, 2.3), "mantel": (1.2, 2.3)}[KINDS[label]]
    assert lo <= size <= hi, (KINDS[label], size)


def test_the_dataset_is_every_kind_with_sizes_kept_through_its_cache(tmp_path):
    ds = near_unknowns("train", cache_dir=tmp_path, per_class=2)
    assert ds.classes == list(KINDS) and np.bincount(ds.labels()).tolist() == [2] * len(KINDS)
    for i, (source, label) in enumerate(ds.items):
        assert ds.size(i) == pytest.approx(make_near(label, int(source.split("/")[1]))[2], rel=1e-9)
    again = near_unknowns("train", cache_dir=tmp_path, per_class=2)
    assert [again.size(i) for i in range(len(again))] == [ds.size(i) for i in range(len(ds))]
    with pytest.raises(InputError, match="split"):
        near_unknowns("test", cache_dir=tmp_path)
