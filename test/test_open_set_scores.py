# Copyright 2026 active_recognition maintainers
# SPDX-License-Identifier: Apache-2.0

"""benchmarks/open_set_scores.py's scores against loops written apart, and its per-class
thresholds on groups whose answer is known."""
import numpy as np
import pytest
from conftest import load_benchmark

scores = load_benchmark("open_set_scores")


def test_knn_is_the_kth_smallest_cosine_distance_of_its_step():
    rng = np.random.default_rng(3)
    reference, states = rng.normal(size=(7, 2, 4)), rng.normal(size=(5, 2, 4))
    for k in (1, 3, 7):
        got = scores.knn(reference, states, k)
        for i in range(5):
            for t in range(2):
                d = sorted(1 - np.dot(states[i, t], r) / np.linalg.norm(states[i, t]) / np.linalg.norm(r)
                           for r in reference[:, t])
                assert got[i, t] == pytest.approx(d[k - 1])
    same = scores.knn(reference, reference, 1)
    np.testing.assert_allclose(same, 0, atol=1e-12)  # each reference state is its own nearest


def test_per_class_thresholds_follow_each_answered_class():
    rng = np.random.default_rng(0)
    # class 0's known scores lie near 0, class 1's near 10: one global threshold would pass
    # every unknown answered 0 that scores 5; per class, those are flagged and class 1's are not
    answers = np.repeat([0, 1], 200)
    known = np.where(answers == 0, rng.uniform(0, 1, 400), rng.uniform(9, 11, 400))
    unknown, unknown_answers = np.full(10, 5.0), np.repeat([0, 1], 5)
    rejected, flagged = scores.per_class(known, answers, unknown, unknown_answers, 0.05, classes=2)
    assert flagged == pytest.approx(0.5)
    assert 0.02 < rejected < 0.09  # about 5 %, measured on the half each threshold did not see
    assert scores.flagged_at(known, unknown, 0.05) == 0.0  # the global threshold sits near 11
