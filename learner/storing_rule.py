"""The storing rule: which sensory blocks of a feedback changed, hence which models store it.

Two rules (LearnerConfig.storing_rule; docs/protocol.md §11):
- "moved_from_start", the paper's "only when its sensory part changed": a block with a start
  position in the context (stick handle, toy i) changed when one of its 5 x, 5 y samples is
  more than `tolerance` from that start position. The context is the position before the
  movement, so a toy grabbed before the first sample (step 1 of 50) still counts as moved,
  which comparing the samples with each other would miss. The hand block has no start in the
  context: it changed when a sample differs from the first sample (its start is always the
  rest position, reached again only by a still arm). The sound block changed when a value is
  more than the tolerance from 0, the silent block the world sends;
- "varies_about_mean", the study's code: |x - mean x| + |y - mean y| > tolerance over the
  block's 5 x and 5 y samples (F1 and F2 for the sound).

Both are compiled (numba; every iteration runs one, and as a dozen NumPy calls on arrays of
60 values it was mostly call overhead). The study's rule does arithmetic: its kernel adds in
the order NumPy's reductions of these shapes add, so the spreads are NumPy's to the last bit
(tests/learner/test_storing_rule.py holds it to the NumPy expression).
"""

from __future__ import annotations

import numpy as np

from learner.compiled import compiled
from models.layout import (
    CONTEXT_DIM,
    CONTEXT_SLOTS,
    N_SAMPLES,
    SENSORY_BLOCKS,
    SENSORY_DIM,
    block_slice,
    context_indices,
)

_N_BLOCKS = len(SENSORY_BLOCKS)
_SILENT = -1  # a value compared with 0


def _reference_sources() -> np.ndarray:
    """(60,) where each value of s is compared to under "moved_from_start": index i < 10 is
    context[i], i >= 10 is s[i - 10] (the hand's first sample), _SILENT is 0."""
    sources = np.full(SENSORY_DIM, _SILENT, dtype=np.intp)
    for block in SENSORY_BLOCKS:
        if block == "sound":
            continue
        dims = np.arange(SENSORY_DIM)[block_slice(block)].reshape(2, N_SAMPLES)  # x row, y row
        for axis in range(2):
            if block in CONTEXT_SLOTS:
                sources[dims[axis]] = context_indices(block)[axis]
            else:  # the hand: its own first sample
                sources[dims[axis]] = CONTEXT_DIM + dims[axis, 0]
    return sources


_SOURCES = _reference_sources()


@compiled
def _moved_from_start(
    context: np.ndarray, s: np.ndarray, tolerance: float, sources: np.ndarray, out: np.ndarray
) -> None:  # pragma: no cover - compiled; tested against the NumPy expression
    block_dim = 2 * N_SAMPLES
    for b in range(_N_BLOCKS):
        moved = False
        for i in range(b * block_dim, (b + 1) * block_dim):
            source = sources[i]
            if source == _SILENT:
                reference = 0.0
            elif source < CONTEXT_DIM:
                reference = context[source]
            else:
                reference = s[source - CONTEXT_DIM]
            moved = moved or abs(s[i] - reference) > tolerance
        out[b] = moved


@compiled
def block_spreads(s: np.ndarray) -> np.ndarray:  # pragma: no cover - compiled; tested
    """(6,) |x - mean x| + |y - mean y| of each block of s (60,), with NumPy's arithmetic: a
    sum over the 5 samples adds them first to last, the mean divides that sum by 5, the
    Euclidean length is the root of such a sum of squares."""
    spreads = np.empty(_N_BLOCKS)
    for b in range(_N_BLOCKS):
        spread = 0.0
        for axis in range(2):
            first = (2 * b + axis) * N_SAMPLES
            total = s[first]
            for i in range(first + 1, first + N_SAMPLES):
                total += s[i]
            mean = total / N_SAMPLES
            d = s[first] - mean
            squares = d * d
            for i in range(first + 1, first + N_SAMPLES):
                d = s[i] - mean
                squares += d * d
            spread = np.sqrt(squares) if axis == 0 else spread + np.sqrt(squares)
        spreads[b] = spread
    return spreads


def changed_blocks(
    context: np.ndarray, s: np.ndarray, tolerance: float, rule: str = "moved_from_start"
) -> np.ndarray:
    """The storing rule for every block of SENSORY_BLOCKS at once: (6,) bool, from a checked
    float64 context (10,) and feedback (60,)."""
    if rule == "varies_about_mean":
        return block_spreads(s) > tolerance
    changed = np.empty(_N_BLOCKS, dtype=np.bool_)
    _moved_from_start(context, s, tolerance, _SOURCES, changed)
    return changed
