"""Exact Euclidean nearest-neighbour memory of rows that grow one at a time.

Why not a plain k-d tree: the agent's hot query is the inverse model's, with a goal drawn
uniformly in [-1, 1]^10, far from the data, in 10 to 38 dimensions. A k-d tree must then open
most of its leaves: scipy's cKDTree measured 0.2 to 2.8 times the time of a plain NumPy scan at
80000 rows.

What this memory does instead is a scan made cheap, in two stages, with the same answer as
`brute_force_nearest` (including which row wins a tie: the lowest index), and, for memories
longer than a study-length trial's, trees made for that scan (3.):

1. Screening (learner/quantized_scan.py): every row is also kept as 8-bit codes on a grid of
   step `scale / 127`; a compiled kernel computes the query's distance to every row's codes in
   float32 and returns the rows that a rigorous bound of quantisation and rounding error allows
   to be the nearest. Usually that is one row.
2. Exact re-ranking, float64: the candidates are re-ranked with the very expression of the
   brute-force reference.
3. Long development (learner/code_tree.py, learner/indexed_screen.py): from 2 x TREE_ROWS rows
   on, the older rows are also sorted into static k-d trees over runs of TREE_ROWS x 2^k rows,
   merged as a binary counter counts, and a query screens only the newest rows block by
   block and the trees' leaves whose boxes can hold a candidate. The candidates still hold
   every row at the nearest distance, so stage 2 gives the same answer.

The grid's `scale` is the smallest power of two, at least 1, above every stored |value|: the
agent's spaces lie in [-1, 1], so it is 1; a larger value re-codes every row (rarely: at most
once per doubling). The scale follows from the rows alone, so a memory rebuilt from its
`state_dict` answers identically. Appends write one row into preallocated arrays that double
when full (amortised O(dim)).
"""

from __future__ import annotations

import math
from typing import cast

import numpy as np
from numpy.typing import ArrayLike

from learner.code_tree import FANOUT, LEAF_ROWS, build_tree, tree_levels
from learner.indexed_screen import screen_query
from learner.quantized_scan import BLOCK_ROWS, CODE_MAX, store_row

_INITIAL_CAPACITY = 1024
# Rows of the smallest tree (learner/code_tree.py). A memory builds its first trees at twice
# this, and then screens block by block fewer than this past its trees: a memory of a
# study-length trial (at most about 50000 rows) or of `playroom bench`'s learner (80000) holds
# none and is screened as before trees.
TREE_ROWS = 2**16


def squared_distances(rows: np.ndarray, query: np.ndarray) -> np.ndarray:
    """Squared Euclidean distances (n,) from rows (n, dim) to query (dim,), in float64.

    Both the memory's re-ranking and the brute-force reference use this one expression, so a
    row's distance is the same number whichever of them computes it.
    """
    diff = rows - query
    return np.einsum("ij,ij->i", diff, diff)


def brute_force_nearest(rows: ArrayLike, query: ArrayLike) -> tuple[int, float]:
    """Reference scan: (index of the nearest row, its Euclidean distance); ties -> lowest index.

    rows (n, dim), query (dim,).
    """
    rows = np.asarray(rows, dtype=np.float64)
    query = np.asarray(query, dtype=np.float64)
    if rows.shape[0] == 0:
        raise ValueError("nearest neighbour of an empty set of rows")
    sq = squared_distances(rows, query)
    i = int(np.argmin(sq))
    return i, float(np.sqrt(sq[i]))


def _scale_for(max_abs: float) -> float:
    """The grid's scale for rows whose largest |value| is max_abs: a power of two, >= 1."""
    if max_abs <= 1.0:
        return 1.0
    return 2.0 ** math.ceil(math.log2(max_abs))


class NearestNeighbourMemory:
    """Rows of `dim` floats, appended one at a time, with exact nearest-neighbour queries."""

    def __init__(
        self, dim: int, capacity: int = _INITIAL_CAPACITY, tree_rows: int = TREE_ROWS
    ) -> None:
        if not isinstance(dim, int | np.integer) or dim <= 0:
            raise ValueError(f"memory dimension must be a positive integer, got {dim!r}")
        if tree_rows < BLOCK_ROWS or tree_rows % BLOCK_ROWS or tree_rows & (tree_rows - 1):
            raise ValueError(
                f"tree_rows must be a power of two and a multiple of {BLOCK_ROWS}, got {tree_rows}"
            )
        self._dim = int(dim)
        self._n = 0
        self._scale = 1.0  # grid step is scale / CODE_MAX
        self._tree_rows = int(tree_rows)
        self._allocate(max(int(capacity), 1))
        self._drop_trees()

    @property
    def dim(self) -> int:
        return self._dim

    def __len__(self) -> int:
        return self._n

    @property
    def rows(self) -> np.ndarray:
        """The stored rows (n, dim), float64, read-only view."""
        view = self._rows[: self._n]
        view.flags.writeable = False
        return view

    def append(self, row: ArrayLike, checked: bool = False) -> None:
        """Add one row (dim,). Raises ValueError on a wrong shape or a non-finite value, unless
        the caller has `checked` the row already (a float64 array of finite values)."""
        values = cast(np.ndarray, row)  # as the caller checked it
        if not checked:
            values = np.asarray(row, dtype=np.float64)
            if values.shape != (self._dim,):
                raise ValueError(f"memory row must have shape ({self._dim},), got {values.shape}")
            if not np.isfinite(values).all():
                raise ValueError("memory row has a NaN or infinite value")
        if self._n == self._rows.shape[0]:
            self._reserve(self._n + 1)
        n = self._n
        self._n = n + 1
        # _code_from's arithmetic for one row, compiled (every iteration stores a row or two).
        if not store_row(self._rows, self._codes, n, values, self._scale):
            self._code_from(n)  # beyond the grid: widened, every row re-coded
        elif self._n >= self._next_trees:
            self._grow_trees()

    def extend(self, rows: ArrayLike) -> None:
        """Add rows (k, dim) at once, as k appends would."""
        rows = np.asarray(rows, dtype=np.float64)
        if rows.ndim != 2 or rows.shape[1] != self._dim:
            raise ValueError(f"memory rows must have shape (k, {self._dim}), got {rows.shape}")
        if not np.isfinite(rows).all():
            raise ValueError("memory rows have a NaN or infinite value")
        k = rows.shape[0]
        if k == 0:
            return
        self._reserve(self._n + k)
        n = self._n
        self._rows[n : n + k] = rows
        self._n = n + k
        self._code_from(n)

    def trees(self) -> list[tuple[int, int]]:
        """The trees' runs of rows (first row, rows), oldest first (learner/code_tree.py)."""
        return list(self._runs)

    @property
    def rows_past_trees(self) -> int:
        """The newest rows, which no tree holds: a query screens them block by block."""
        return self._n - self._tail

    def nearest(self, query: ArrayLike) -> tuple[int, float]:
        """(index of the nearest row, Euclidean distance), as `brute_force_nearest` answers.

        query (dim,). Raises ValueError if the memory is empty or the query is malformed.
        """
        q = self._checked_query(query)
        best, distance = self._search(q)
        if distance is None:
            distance = float(np.sqrt(squared_distances(self._rows[best : best + 1], q)[0]))
        return best, distance

    def nearest_index(self, query: ArrayLike) -> int:
        """The index `nearest` answers, without computing its distance (the learner's inverse
        query needs only the row)."""
        return self._search(self._checked_query(query))[0]

    def _checked_query(self, query: ArrayLike) -> np.ndarray:
        q = np.asarray(query, dtype=np.float64)
        if q.shape != (self._dim,):
            raise ValueError(f"query must have shape ({self._dim},), got {q.shape}")
        if not np.logical_and.reduce(np.isfinite(q)):  # q.all()'s answer, without its wrapper
            raise ValueError("query has a NaN or infinite value")
        if self._n == 0:
            raise ValueError("nearest neighbour asked of an empty memory")
        return q

    def _search(self, q: np.ndarray) -> tuple[int, float | None]:
        """(index of the nearest row, its distance, or None where a single candidate made
        computing it unnecessary) for a checked query."""
        n = self._n
        trees = (
            self._tail,
            self._tree_table,
            self._levels,
            self._order,
            self._leaf_codes,
            self._boxes,
        )
        scratch = (self._block_squares, self._block_min, self._candidates, self._squares)
        count = screen_query(self._codes, self._rows, n, q, self._scale, trees, scratch)
        if count < 0:  # far outside the grid: scanned exactly
            return brute_force_nearest(self._rows[:n], q)
        if count == 1:
            return int(self._candidates[0]), None
        # In increasing index order, so argmin's first minimum is the lowest index of a tie.
        candidates = self._candidates[:count]
        if self._runs:  # the trees' candidates come in their leaves' order
            candidates = np.sort(candidates)
        squared = squared_distances(self._rows[candidates], q)
        j = int(squared.argmin())
        return int(candidates[j]), float(np.sqrt(squared[j]))

    def state_dict(self) -> dict[str, np.ndarray]:
        """{'rows': (n, dim) float64 copy}: plain arrays for np.savez."""
        return {"rows": self._rows[: self._n].copy()}

    def load_state_dict(self, state: dict[str, np.ndarray]) -> None:
        """Replace the content by a `state_dict()`; answers are then identical."""
        rows = np.asarray(state["rows"], dtype=np.float64)
        if rows.ndim != 2 or rows.shape[1] != self._dim:
            raise ValueError(
                f"memory state rows must have shape (n, {self._dim}), got {rows.shape}"
            )
        self._n = 0
        self._scale = 1.0
        self._allocate(_INITIAL_CAPACITY)
        self._drop_trees()
        self.extend(rows)

    def nbytes(self) -> int:
        """Bytes held by the preallocated arrays."""
        arrays = (self._rows, self._codes, self._block_squares, self._block_min, self._candidates)
        trees = (self._squares, self._order, self._leaf_codes, self._boxes)
        return sum(a.nbytes for a in arrays + trees)

    def _allocate(self, capacity: int) -> None:
        """Empty arrays for `capacity` rows (the first `self._n` are copied by the caller)."""
        self._rows = np.empty((capacity, self._dim))  # float64, what the answers are made of
        # Codes block by block (learner/quantized_scan.py): row i at [i // BLOCK_ROWS, :,
        # i % BLOCK_ROWS], so that a block's codes are contiguous and a scan one stream.
        n_blocks = -(-capacity // BLOCK_ROWS)
        self._codes = np.zeros((n_blocks, self._dim, BLOCK_ROWS), dtype=np.int8)
        self._block_squares = np.empty(BLOCK_ROWS, dtype=np.float32)  # the kernel's scratch
        self._block_min = np.empty(n_blocks + 1, dtype=np.float32)
        self._candidates = np.empty(capacity, dtype=np.intp)
        self._squares = np.empty(capacity, dtype=np.float32)  # the candidates' b^2
        # The trees (learner/code_tree.py), in arrays indexed by row, leaf and node: empty in
        # a memory too small for trees.
        trees = capacity >= 2 * self._tree_rows
        n_leaves = capacity // LEAF_ROWS if trees else 0
        self._order = np.empty(capacity if trees else 0, dtype=np.intp)
        self._leaf_codes = np.empty((n_leaves, self._dim, LEAF_ROWS), dtype=np.int8)

    def _reserve(self, n_rows: int) -> None:
        """Make room for n_rows, doubling the capacity as often as needed."""
        capacity = self._rows.shape[0]
        if n_rows <= capacity:
            return
        while capacity < n_rows:
            capacity *= 2
        old: list[np.ndarray] = [self._rows[: self._n], self._codes, self._order, self._leaf_codes]
        self._allocate(capacity)
        grown: list[np.ndarray] = [self._rows, self._codes, self._order, self._leaf_codes]
        for new, kept in zip(grown, old, strict=True):
            new[: len(kept)] = kept

    def _code_from(self, start: int) -> None:
        """Write the codes of the rows from `start` on; a value beyond the grid widens it and
        re-codes every stored row."""
        max_abs = float(np.abs(self._rows[start : self._n]).max())
        if max_abs > self._scale:
            self._scale = _scale_for(max_abs)
            start = 0
            self._drop_trees()  # the grid changed: rebuilt below, from the rows
        codes = np.rint(self._rows[start : self._n].T * (CODE_MAX / self._scale))
        for b in range(start // BLOCK_ROWS, -(-self._n // BLOCK_ROWS)):  # the blocks written
            first, end = max(start, b * BLOCK_ROWS), min(self._n, (b + 1) * BLOCK_ROWS)
            self._codes[b, :, first - b * BLOCK_ROWS : end - b * BLOCK_ROWS] = codes[
                :, first - start : end - start
            ]
        if self._n >= self._next_trees:
            self._grow_trees()

    def _drop_trees(self) -> None:
        self._runs: list[tuple[int, int]] = []  # each tree's first row and rows
        self._tree_levels: list[list[int]] = []  # each tree's levels' first blocks in _boxes
        self._boxes = np.empty((0, 2, self._dim, FANOUT), dtype=np.float32)
        self._tail = 0  # the first row no tree holds
        self._next_trees = 2 * self._tree_rows  # rows at which the trees grow next
        self._table_trees()

    def _grow_trees(self) -> None:
        """Trees over every whole `tree_rows` of rows, as a binary counter counts them: runs of
        tree_rows times the powers of two of that count, largest (oldest rows) first. Two
        trees of one size become one of twice the size, so a row is sorted into a tree about
        log2(n / tree_rows) times over the memory's life and a query searches as many trees.
        Trees whose rows do not change are kept."""
        chunks = self._n // self._tree_rows
        wanted, first = [], 0
        for bit in range(chunks.bit_length() - 1, -1, -1):
            if chunks >> bit & 1:
                wanted.append((first, self._tree_rows << bit))
                first += self._tree_rows << bit
        kept = 0
        while kept < min(len(wanted), len(self._runs)) and self._runs[kept] == wanted[kept]:
            kept += 1
        levels = self._tree_levels[:kept]
        end = levels[-1][-1] if levels else 0  # blocks of boxes the kept trees use
        for _, size in wanted[kept:]:
            levels.append([end + start for start in tree_levels(size // LEAF_ROWS)])
            end = levels[-1][-1]
        if end > len(self._boxes):  # room for the new trees' boxes, the kept ones copied
            boxes = np.empty((2 * end, 2, self._dim, FANOUT), dtype=np.float32)
            boxes[: len(self._boxes)] = self._boxes
            self._boxes = boxes
        for k in range(kept, len(wanted)):
            arrays = (self._order, self._leaf_codes, self._boxes, np.array(levels[k]))
            build_tree(self._rows, self._codes, *wanted[k], *arrays)
        self._runs, self._tree_levels = wanted, levels
        self._tail = first  # the first row no tree holds: where the loop above left it
        self._next_trees = first + self._tree_rows
        self._table_trees()

    def _table_trees(self) -> None:
        """The trees as the screen's kernel reads them: (first row, levels' count) each, and
        their levels' first blocks, a row each."""
        width = max((len(levels) for levels in self._tree_levels), default=1)
        table = [
            (first, len(levels))
            for (first, _), levels in zip(self._runs, self._tree_levels, strict=True)
        ]
        self._tree_table = np.array(table, dtype=np.int64).reshape(-1, 2)
        padded = [levels + [0] * (width - len(levels)) for levels in self._tree_levels]
        self._levels = np.array(padded, dtype=np.int64).reshape(-1, width)
