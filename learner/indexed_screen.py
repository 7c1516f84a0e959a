"""The screen of a memory whose older rows are in trees: the newest rows block by block
(learner/quantized_scan.py), the older ones tree by tree (learner/code_tree.py), one limit.

Every part bounds the nearest row's distance from above, in code units (`nearest`): the
blocks' smallest value (candidate_limit's bound), then the exact float64 distance of the
newest rows' candidates and of each tree leaf's best row, which takes the grid's slack out of
the bound. A row is a candidate when its screening value is at most `screening_limit` of that
bound: a row beyond it is farther than some row. So the candidates hold every row at the
nearest distance, ties included, and re-ranking them exactly gives the brute-force answer.
Without trees this is quantized_scan's screen, unchanged.
"""

from __future__ import annotations

import math

import numpy as np

from learner.code_tree import (
    EXACT_MARGIN,
    FANOUT,
    LEAF_ROWS,
    build_tree,
    distance,
    search_tree,
    tree_levels,
)
from learner.compiled import compiled
from learner.quantized_scan import (
    BLOCK_ROWS,
    CODE_MAX,
    FAR_QUERY_CODES,
    block_candidates,
    block_minima,
    candidate_limit,
    screen_candidates,
    screening_limit,
    store_row,
)


@compiled
def screen_query(
    codes: np.ndarray,
    rows: np.ndarray,
    n: int,
    q: np.ndarray,
    scale: float,
    trees: tuple,
    scratch: tuple,
) -> int:  # pragma: no cover - compiled; its answers are tested against brute force
    """Write the candidates' row indices into scratch's `candidates` for a float64 query q
    (dim,) and return their count, or -1 for a query too far outside the grid for float32
    sums (FAR_QUERY_CODES), which the caller scans exactly.

    codes: the memory's 8-bit codes (quantized_scan), of grid `scale`; rows (>= n, dim)
    float64; trees: (tail, runs, levels, order, leaf_codes, boxes): the rows before `tail` lie
    in the trees of `runs` ((k, 2) int64: each tree's first row and the length of its row of
    `levels`, its levels' first blocks in `boxes`), laid out as code_tree lays them; scratch:
    (block_squares, block_min, candidates, candidate_squares), the last two of n or more. The
    candidates come in increasing order without trees, the trees' first with.
    """
    tail, runs, levels, order, leaf_codes, boxes = trees
    block_squares, block_min, candidates, candidate_squares = scratch
    dim = q.shape[0]
    code_scale = CODE_MAX / scale
    query = np.empty(dim, np.float32)
    largest, norm2 = 0.0, 0.0
    for d in range(dim):
        v = q[d] * code_scale
        largest = max(largest, abs(v))
        norm2 += v * v
        query[d] = np.float32(v)
    if not largest < FAR_QUERY_CODES:
        return -1
    eta, rho = candidate_limit(dim, math.sqrt(norm2))
    if runs.shape[0] == 0:
        return screen_candidates(codes, n, query, eta, rho, block_squares, block_min, candidates)
    nearest = np.inf
    best = block_minima(codes, tail, n, query, block_squares, block_min)
    if best < np.inf:
        limit = screening_limit(math.sqrt(best) / (1.0 - rho) + eta, eta, rho)
        count = block_candidates(
            codes, tail, n, query, limit, block_squares, block_min, candidates, 0
        )
        for j in range(count):  # their exact distances: a bound free of the grid's slack
            exact = distance(rows, candidates[j], q) * code_scale
            nearest = min(nearest, exact * (1.0 + EXACT_MARGIN))
    recorded = 0
    for r in range(runs.shape[0]):
        tree = (runs[r, 0], levels[r, : runs[r, 1]], boxes, order, leaf_codes, rows)
        nearest, recorded = search_tree(
            tree, q, query, code_scale, eta, rho, nearest, scratch, recorded
        )
    limit = screening_limit(nearest, eta, rho)
    count = 0
    for j in range(recorded):  # what the trees recorded under a limit since lowered
        if candidate_squares[j] <= limit:
            candidates[count] = candidates[j]
            count += 1
    return block_candidates(
        codes, tail, n, query, limit, block_squares, block_min, candidates, count
    )


def warm_up() -> None:
    """Load (or, on a first run, compile and cache) the memory's kernels now rather than at the
    first store, query and tree: once per process, 0.2 s from numba's cache, a few seconds to
    compile."""
    dim, rows = 1, BLOCK_ROWS  # one tree of a whole block: no row past it
    codes = np.zeros((1, dim, BLOCK_ROWS), dtype=np.int8)
    values = np.zeros((rows, dim))
    store_row(values, codes, 0, np.zeros(dim), 1.0)
    order = np.empty(rows, np.intp)
    leaf_codes = np.empty((rows // LEAF_ROWS, dim, LEAF_ROWS), np.int8)
    levels = np.array(tree_levels(rows // LEAF_ROWS), dtype=np.int64)
    boxes = np.empty((levels[-1], 2, dim, FANOUT), np.float32)
    build_tree(values, codes, 0, rows, order, leaf_codes, boxes, levels)
    trees = (rows, np.array([[0, len(levels)]]), levels[None, :], order, leaf_codes, boxes)
    squares = np.empty(BLOCK_ROWS, np.float32)
    scratch = (squares, squares[:2].copy(), np.empty(rows, np.intp), np.empty(rows, np.float32))
    screen_query(codes, values, rows, np.zeros(dim), 1.0, trees, scratch)
