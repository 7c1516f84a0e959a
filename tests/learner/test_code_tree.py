"""A memory whose older rows are sorted into trees (learner/code_tree.py) answers exactly as the
brute-force scan does, ties included, however its trees grow, merge, are restored or re-coded."""

from __future__ import annotations

import numpy as np
import pytest

from learner.memory import TREE_ROWS, NearestNeighbourMemory, brute_force_nearest

SMALL_TREES = 1024  # the smallest tree allowed: trees from 2048 rows on


def _arm_like_rows(rng: np.random.Generator, n: int, dim: int = 10) -> np.ndarray:
    """Rows near a 3-parameter surface, as an arm model's outcomes lie, with exact repeats."""
    params = rng.uniform(-1, 1, (n, 3))
    basis = rng.normal(0, 0.3, (3, dim))
    rows = np.tanh(params @ basis) + rng.normal(0, 0.01, (n, dim))
    rows[n // 3 : n // 3 + 40] = rows[7]  # a tie spread over the trees and the newest rows
    rows[-40:] = rows[n // 2]
    return rows


def _sound_like_rows(rng: np.random.Generator, n: int) -> np.ndarray:
    """Rows of 8 context values and one of 6 sounds (10 values), as the sound model's are."""
    sounds = rng.uniform(-1, 1, (6, 10))
    contexts = np.round(rng.uniform(-1, 1, (n, 8)), 2)  # rounded: many contexts repeat
    return np.hstack((contexts, sounds[rng.integers(0, 6, n)]))


def _queries(rng: np.random.Generator, rows: np.ndarray, k: int = 12) -> np.ndarray:
    dim = rows.shape[1]
    far_goals = rng.uniform(-1, 1, (k, dim))  # goal babbling's goals: far from the rows
    far_goals[:, : dim - 10] = rows[rng.integers(0, len(rows), k), : dim - 10]
    near = rows[rng.integers(0, len(rows), k)] + rng.normal(0, 1e-3, (k, dim))
    exact = rows[rng.integers(0, len(rows), k)]  # on a row: ties with its repeats
    return np.vstack((far_goals, near, exact, rng.uniform(-3, 3, (k, dim))))


def _assert_brute_force(memory: NearestNeighbourMemory, rows: np.ndarray, queries) -> None:
    for q in queries:
        want = brute_force_nearest(rows, q)
        assert memory.nearest(q) == want
        assert memory.nearest_index(q) == want[0]


@pytest.mark.parametrize("shape", ["arm", "sound"])
def test_trees_answer_as_brute_force_as_they_grow_and_merge(shape: str) -> None:
    rng = np.random.default_rng(1 if shape == "arm" else 2)
    rows = _arm_like_rows(rng, 7300) if shape == "arm" else _sound_like_rows(rng, 7300)
    memory = NearestNeighbourMemory(rows.shape[1], tree_rows=SMALL_TREES)
    checked = {2047, 2048, 3072, 4095, 4096, 5121, 7168, 7300}
    for n, row in enumerate(rows, start=1):
        memory.append(row)
        if n in checked:
            _assert_brute_force(memory, rows[:n], _queries(rng, rows[:n]))
        if n >= 2 * SMALL_TREES:  # every row but the newest in a tree, each in one
            runs = memory.trees()
            assert [first for first, _ in runs] == list(np.cumsum([0] + [s for _, s in runs])[:-1])
            assert n - sum(size for _, size in runs) == memory.rows_past_trees < SMALL_TREES
    # Seven whole runs of 1024 as a binary counter counts them: 4096 + 2048 + 1024.
    assert memory.trees() == [(0, 4096), (4096, 2048), (6144, 1024)]
    assert memory.rows_past_trees == 7300 - 7168


def test_a_memory_below_two_trees_is_screened_as_before() -> None:
    """No trees below 2 x TREE_ROWS rows: a study-length trial's memories (at most about 50000
    rows) are searched exactly as before the trees."""
    rng = np.random.default_rng(3)
    memory = NearestNeighbourMemory(10)
    memory.extend(rng.uniform(-1, 1, (2 * TREE_ROWS - 1, 10)))
    assert memory.trees() == []
    memory.append(np.zeros(10))
    assert memory.trees() == [(0, 2 * TREE_ROWS)]


def test_restored_and_extended_memories_hold_the_same_trees_and_answers() -> None:
    rng = np.random.default_rng(4)
    rows = _arm_like_rows(rng, 5000, dim=14)
    grown = NearestNeighbourMemory(14, tree_rows=SMALL_TREES)
    for row in rows:
        grown.append(row)
    restored = NearestNeighbourMemory(14, tree_rows=SMALL_TREES)
    restored.load_state_dict(grown.state_dict())
    assert restored.trees() == grown.trees() == [(0, 4096)]
    for q in _queries(rng, rows):
        assert restored.nearest(q) == grown.nearest(q) == brute_force_nearest(rows, q)


def test_a_row_beyond_the_grid_recodes_the_trees() -> None:
    """A value beyond the grid widens it and re-codes every row: the trees are rebuilt from
    the new codes, and the answers stay the brute-force ones."""
    rng = np.random.default_rng(5)
    rows = _arm_like_rows(rng, 4500)
    memory = NearestNeighbourMemory(10, tree_rows=SMALL_TREES)
    memory.extend(rows[:4400])
    wide = np.full(10, 3.0)
    memory.append(wide)
    for row in rows[4400:]:
        memory.append(row)
    everything = np.vstack((rows[:4400], wide, rows[4400:]))
    assert memory.trees() == [(0, 4096)]
    _assert_brute_force(memory, everything, _queries(rng, everything))


def test_a_query_far_outside_the_grid_is_scanned_exactly_with_trees() -> None:
    rng = np.random.default_rng(6)
    rows = _arm_like_rows(rng, 3000)
    memory = NearestNeighbourMemory(10, tree_rows=SMALL_TREES)
    memory.extend(rows)
    _assert_brute_force(memory, rows, [np.full(10, 1e17), np.full(10, -1e300)])


@pytest.mark.parametrize("tree_rows", [1000, 3072, 512])
def test_tree_rows_must_be_a_power_of_two_of_whole_blocks(tree_rows: int) -> None:
    with pytest.raises(ValueError, match="tree_rows must be a power of two"):
        NearestNeighbourMemory(10, tree_rows=tree_rows)


def test_a_memory_of_the_default_tree_size_answers_as_brute_force() -> None:
    """At the default sizes a long trial's memories reach: trees of 131072 and 65536 rows and
    the newest rows past them, grown one row at a time."""
    rng = np.random.default_rng(7)
    rows = _arm_like_rows(rng, 3 * TREE_ROWS + 3000)
    memory = NearestNeighbourMemory(10)
    for row in rows:
        memory.append(row, checked=True)
    assert memory.trees() == [(0, 2 * TREE_ROWS), (2 * TREE_ROWS, TREE_ROWS)]
    assert memory.rows_past_trees == 3000
    _assert_brute_force(memory, rows, _queries(rng, rows, k=8))
