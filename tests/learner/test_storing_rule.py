"""The compiled storing rules give the NumPy expressions' answers, the study's spreads to the
last bit: a different order of additions would store other experiences near the tolerance."""

from __future__ import annotations

import numpy as np

from learner.storing_rule import block_spreads, changed_blocks
from models.layout import CONTEXT_SLOTS, N_SAMPLES, SENSORY_BLOCKS, block_slice, context_indices


def _spreads_in_numpy(s: np.ndarray) -> np.ndarray:
    xy = s.reshape(len(SENSORY_BLOCKS), 2, N_SAMPLES)
    about_mean = xy - xy.mean(axis=2, keepdims=True)
    return np.linalg.norm(about_mean, axis=2).sum(axis=1)


def _moved_in_numpy(context: np.ndarray, s: np.ndarray, tolerance: float) -> np.ndarray:
    moved = []
    for block in SENSORY_BLOCKS:
        xy = s[block_slice(block)].reshape(2, N_SAMPLES)
        if block == "sound":
            start = np.zeros((2, 1))
        elif block in CONTEXT_SLOTS:
            start = context[list(context_indices(block))].reshape(2, 1)
        else:  # the hand: its first sample
            start = xy[:, :1]
        moved.append(bool((np.abs(xy - start) > tolerance).any()))
    return np.array(moved)


def _feedbacks(rng: np.random.Generator, n: int) -> np.ndarray:
    """Feedbacks of every scale, some rounded (repeated values, exact means), some still."""
    s = rng.uniform(-1, 1, (n, 60)) * 10.0 ** rng.integers(-8, 2, (n, 1))
    s[::3] = np.round(s[::3], 2)
    s[::7, 10:30] = s[::7, 10:11]  # blocks that did not move
    return s


def test_study_spreads_are_numpys_to_the_last_bit() -> None:
    for s in _feedbacks(np.random.default_rng(0), 20000):
        np.testing.assert_array_equal(
            block_spreads(s).view(np.int64), _spreads_in_numpy(s).view(np.int64)
        )


def test_both_rules_match_their_numpy_expressions() -> None:
    rng = np.random.default_rng(1)
    for s in _feedbacks(rng, 5000):
        context = s[rng.integers(0, 60, 10)] + rng.choice([0.0, 0.005, 0.02], 10)
        tolerance = float(rng.choice([0.0, 0.01, 0.02]))
        np.testing.assert_array_equal(
            changed_blocks(context, s, tolerance, "moved_from_start"),
            _moved_in_numpy(context, s, tolerance),
        )
        np.testing.assert_array_equal(
            changed_blocks(context, s, tolerance, "varies_about_mean"),
            _spreads_in_numpy(s) > tolerance,
        )
