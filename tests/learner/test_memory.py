"""The learner's nearest-neighbour memory answers exactly as a brute-force float64 scan does,
however its 8-bit screening codes round the rows."""

from __future__ import annotations

import numpy as np
import pytest

from learner.memory import NearestNeighbourMemory, brute_force_nearest


def _assert_brute_force(memory: NearestNeighbourMemory, rows: np.ndarray, queries) -> None:
    for q in queries:
        want = brute_force_nearest(rows, q)
        assert memory.nearest(q) == want
        assert memory.nearest_index(q) == want[0]  # the learning loop's query


@pytest.mark.parametrize("dim", [1, 10, 18, 38])
def test_memory_matches_brute_force_as_it_grows(dim: int) -> None:
    rng = np.random.default_rng(dim)
    rows = rng.uniform(-1, 1, (2100, dim))
    memory = NearestNeighbourMemory(dim, capacity=4)
    checkpoints = {1, 2, 3, 4, 5, 1023, 1024, 1025, 2048, 2049, 2100}
    for n, row in enumerate(rows, start=1):
        memory.append(row)
        if n in checkpoints:
            far = rng.uniform(-3, 3, (10, dim))
            near = rows[rng.integers(0, n, 10)] + rng.normal(0, 1e-3, (10, dim))
            _assert_brute_force(memory, rows[:n], np.vstack((far, near)))
    assert len(memory) == 2100
    np.testing.assert_array_equal(memory.rows, rows)


def test_memory_grown_in_pieces_across_its_blocks_matches_brute_force() -> None:
    """Rows added in pieces that start and end inside the kernel's blocks of 1024 rows, the
    grid widened by a late piece (every block re-coded): the same answers as brute force."""
    rng = np.random.default_rng(4)
    rows = rng.uniform(-1, 1, (3500, 12))
    rows[3000:] *= 3.0
    memory = NearestNeighbourMemory(12)
    for start, end in ((0, 700), (700, 701), (701, 2100), (2100, 3000), (3000, 3500)):
        memory.extend(rows[start:end])
        queries = np.vstack((rng.uniform(-1, 1, (10, 12)), rows[start:end][:10] + 1e-4))
        _assert_brute_force(memory, rows[:end], queries)


def test_memory_ties_and_near_ties_follow_brute_force() -> None:
    rng = np.random.default_rng(0)
    base = rng.uniform(-1, 1, (300, 12))
    # Exact duplicates (tie -> lowest index) and rows 1e-9 apart: all share their codes.
    rows = np.vstack((base, base[::-1], base + 1e-9, base - 1e-9))
    memory = NearestNeighbourMemory(12)
    memory.extend(rows[:500])
    for row in rows[500:]:
        memory.append(row)
    queries = np.vstack((base[:50] + rng.normal(0, 1e-6, (50, 12)), base[50:100]))
    _assert_brute_force(memory, rows, queries)


def test_memory_is_exact_within_one_grid_step() -> None:
    """Thousands of rows closer together than the codes' step (1/127): the screen cannot tell
    them apart, the re-ranking must."""
    rng = np.random.default_rng(2)
    rows = rng.uniform(0.3, 0.3 + 2e-3, (5000, 14))
    memory = NearestNeighbourMemory(14)
    memory.extend(rows)
    queries = np.vstack((rows[:20] + rng.normal(0, 1e-4, (20, 14)), rng.uniform(-1, 1, (20, 14))))
    _assert_brute_force(memory, rows, queries)


def test_memory_widens_its_grid_for_large_values() -> None:
    """Values beyond [-1, 1] (a large one arriving late re-codes every row) and queries far
    outside the rows, up to values float32 cannot hold, keep exact answers."""
    rng = np.random.default_rng(3)
    rows = rng.uniform(-1, 1, (3000, 10))
    rows[1500] = 40.0
    rows[2500:] *= 1e3
    memory = NearestNeighbourMemory(10)
    for n, row in enumerate(rows, start=1):
        memory.append(row)
        if n in (1499, 1500, 1501, 2600, 3000):
            queries = np.vstack((rng.uniform(-2, 2, (10, 10)), rows[:n][-5:] + 1e-7))
            _assert_brute_force(memory, rows[:n], queries)
    _assert_brute_force(memory, rows, [np.full(10, 1e200), np.full(10, -3e39)])
    extended = NearestNeighbourMemory(10)
    extended.extend(rows)  # the same grid as one row at a time
    _assert_brute_force(extended, rows, rng.uniform(-50, 50, (20, 10)))


def test_memory_state_round_trip_gives_identical_answers(savez_round_trip) -> None:
    rng = np.random.default_rng(1)
    rows = rng.uniform(-1, 1, (1500, 14))
    rows[700] = 3.0  # the grid is rebuilt from the rows alone
    memory = NearestNeighbourMemory(14)
    for row in rows[:1000]:
        memory.append(row)
    restored = NearestNeighbourMemory(14)
    restored.load_state_dict(savez_round_trip(memory.state_dict()))
    for row in rows[1000:]:  # both keep growing after the restore
        memory.append(row)
        restored.append(row)
    for q in rng.uniform(-2, 2, (50, 14)):
        assert restored.nearest(q) == memory.nearest(q) == brute_force_nearest(rows, q)


def test_memory_rejects_bad_input() -> None:
    memory = NearestNeighbourMemory(3)
    with pytest.raises(ValueError, match="empty"):
        memory.nearest(np.zeros(3))
    with pytest.raises(ValueError, match="shape"):
        memory.append(np.zeros(4))
    with pytest.raises(ValueError, match="NaN"):
        memory.append(np.array([0.0, np.nan, 0.0]))
    with pytest.raises(ValueError, match="NaN"):
        memory.extend(np.array([[0.0, np.inf, 0.0]]))
    memory.append(np.zeros(3))
    with pytest.raises(ValueError, match="NaN"):
        memory.nearest(np.array([np.inf, 0.0, 0.0]))
    with pytest.raises(ValueError, match="shape"):
        memory.nearest(np.zeros(2))
    with pytest.raises(ValueError, match="positive"):
        NearestNeighbourMemory(0)
    assert len(memory) == 1  # refused rows were not stored


def test_warm_up_loads_the_kernel_the_memory_uses() -> None:
    """`playroom bench` times the kernel's load apart from the trials: that holds only if the
    warm-up compiles the very specialisations a memory's store and query call."""
    from learner.code_tree import build_tree
    from learner.indexed_screen import screen_query, warm_up
    from learner.quantized_scan import store_row

    kernels = (screen_query, store_row, build_tree)
    warm_up()
    loaded = [set(kernel.signatures) for kernel in kernels]
    memory = NearestNeighbourMemory(14, tree_rows=1024)  # trees from 2048 rows on
    memory.extend(np.random.default_rng(5).uniform(-1, 1, (3000, 14)))
    memory.append(np.full(14, 0.5), checked=True)
    memory.nearest(np.zeros(14))
    assert memory.trees()
    assert [set(kernel.signatures) for kernel in kernels] == loaded


def test_memory_works_where_numba_cannot_cache(run_without_numba_cache) -> None:
    """A read-only install without a writable home: numba finds no cache directory and the
    kernel is compiled in the process."""
    code = (
        "import numpy as np\n"
        "from learner.memory import NearestNeighbourMemory, brute_force_nearest\n"
        "rows = np.random.default_rng(6).uniform(-1, 1, (3000, 12))\n"
        "memory = NearestNeighbourMemory(12)\n"
        "memory.extend(rows)\n"
        "q = np.full(12, 0.5)\n"
        "assert memory.nearest(q) == brute_force_nearest(rows, q)\n"
        "print('exact')\n"
    )
    assert run_without_numba_cache(code) == "exact"


def test_the_cached_kernels_are_dropped_when_any_learner_source_changes(tmp_path) -> None:
    """numba checks a cached kernel against its own file only; a kernel calling another file's
    would keep a stale copy of it. Any change of the package's sources drops every cached
    kernel of it, once."""
    from learner.compiled import forget_stale_kernels

    package = tmp_path / "package"
    (package / "__pycache__").mkdir(parents=True)
    (package / "screen.py").write_text("calls = 'the tree search'\n")
    (package / "tree.py").write_text("LEAF_ROWS = 64\n")
    kernels = [package / "__pycache__" / f"screen.query-12.py311.{ext}" for ext in ("nbi", "nbc")]

    def cache_kernels() -> None:
        for kernel in kernels:
            kernel.write_bytes(b"compiled")

    assert forget_stale_kernels(package)  # no stamp yet: whatever is cached is of unknown code
    cache_kernels()
    assert not forget_stale_kernels(package)
    assert all(kernel.exists() for kernel in kernels)
    (package / "tree.py").write_text("LEAF_ROWS = 128\n")  # another file than the kernel's
    assert forget_stale_kernels(package)
    assert not any(kernel.exists() for kernel in kernels)
    cache_kernels()
    assert not forget_stale_kernels(package)
    assert all(kernel.exists() for kernel in kernels)
