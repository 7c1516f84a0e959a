"""The compiled sums give NumPy's, to the last bit: the learning progress that chooses a model
under active babbling (and is logged under random babbling) must not change with them."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from learner.config import LearnerConfig
from learner.interest import InterestModel, window_progress
from learner.pairwise_sum import BLOCK, pairwise_sum


def _same(x: float, y: float) -> bool:
    return x == y and np.signbit(x) == np.signbit(y)


def test_the_compiled_sum_is_numpys_for_every_length() -> None:
    rng = np.random.default_rng(0)
    for n in range(BLOCK + 1):
        for kind in range(4):
            start = int(rng.integers(0, 5))
            values = rng.normal(0, 1, start + n) * 10.0 ** rng.integers(-6, 6, start + n)
            if kind == 1:
                values = np.round(values, 1)  # repeated values, exact cancellations
            elif kind == 2:
                values[:] = -0.0  # NumPy's sum of negative zeros is 0.0
            got, want = pairwise_sum(values, start, n), np.add.reduce(values[start : start + n])
            assert _same(got, want), (n, kind)
    with pytest.raises(ValueError, match="at most"):
        pairwise_sum(np.zeros(BLOCK + 1), 0, BLOCK + 1)


def test_window_progress_is_the_numpy_expression() -> None:
    rng = np.random.default_rng(1)
    window = 100
    for _ in range(2000):
        ring = -np.abs(rng.normal(0, 1, 2 * window)) * rng.choice([1e-3, 1.0])
        n = int(rng.integers(0, 1000))
        half = min(window, n // 2)
        recent = ring[np.arange(n - 2 * half, n) % (2 * window)]
        want = abs(recent[half:].mean() - recent[:half].mean()) if half else 0.0
        assert _same(window_progress(ring, n, half), want)


@pytest.mark.parametrize("window", [3, 100, 300])  # 300: beyond the compiled sums, in NumPy
def test_an_interest_model_s_progress_is_the_numpy_expression(window: int) -> None:
    config = dataclasses.replace(LearnerConfig(), progress_window=window)
    interest = InterestModel(2, config)
    rng = np.random.default_rng(2)
    competences: list[float] = []
    for _ in range(3 * window):
        goal, reached = rng.uniform(-1, 1, (2, 10))
        competences.append(interest.update(1, goal, reached))
        half = min(window, len(competences) // 2)
        recent = np.array(competences[len(competences) - 2 * half :])
        want = abs(recent[half:].mean() - recent[:half].mean()) if half else 0.0
        assert _same(interest.progress()[1], want)
