"""The compiled kernels of the memory (numba): 8-bit codes screened in float32, and a row stored.

Why a compiled kernel: the inverse query scans every stored row, so its cost is the bytes it
streams. At 80000 rows a float32 copy of the ten models' keys is 46 MB, more than the
machine's 32 MB L3 cache: each query then read its model from main memory (130-190 us). As
8-bit codes the ten models take 12 MB and stay in cache. NumPy cannot compute with int8 codes
without first converting all of them (a full float32 copy per query); numba compiles the loop
below to vector instructions that convert 16 codes at a time.

A row x is stored as codes c = round(x / step), |c| <= 127. For a query q, with q' = q / step
rounded to float32, the kernel computes b_i^2 = sum_d (c_id - q'_d)^2 in float32, in blocks of
rows that stay in the L1 cache, and keeps the smallest value of every block. It then returns
every row whose b_i can belong to the exact nearest row, by the bound of `candidate_limit`.

A memory of more rows than a study-length trial's screens only its newest rows this way and its
older ones through trees whose leaves are laid out as these blocks (learner/code_tree.py).

Codes are stored block by block, (blocks, dim, BLOCK_ROWS): a block's codes are one contiguous
run of memory, so a scan is a single sequential stream the hardware prefetcher follows. (With
one row of codes per dimension the scan read `dim` interleaved streams: measured 25% slower
when the codes had left the cache, as they have by the time the learner queries a model
again.) The squares live only in a block-sized scratch: the few blocks that can hold a
candidate are computed again, the same numbers, rather than writing every row's square out.
"""

from __future__ import annotations

import math

import numpy as np

from learner.compiled import F, compiled

BLOCK_ROWS = 1024  # rows screened together: their float32 sums (4 KB) stay in L1
_LANES = 16  # partial minima kept side by side, so the minimum is taken with vector compares
_F32_UNIT_ROUNDOFF = 2.0**-24
CODE_MAX = 127  # codes are int8 in [-127, 127]


# A query this far outside the grid (in steps) would overflow float32 sums: scanned exactly.
FAR_QUERY_CODES = 1e15


def _compiled(function: F) -> F:
    """`function` compiled with multiply-adds fused (the bound of `candidate_limit` allows it)."""
    return compiled(function, contract=True)


@_compiled  # called by the kernel below (and callable from Python)
def candidate_limit(dim: int, query_code_norm: float) -> tuple[float, float]:
    """(eta, rho) of the screening bound, in code units (distances divided by the step).

    With a_i the exact distance from row i to the query and b_i the kernel's value:
    - quantisation moves a row by at most 0.5 per dimension, and rounding q' to float32 moves
      the query by at most u |q'|: together eta;
    - float32 arithmetic of a dim-term sum of squares errs by at most (dim + 2) u relatively,
      so its square root by half of that; rho is twice (dim + 3) u, for margin.
    Hence (a_i - eta)(1 - rho) <= b_i <= (a_i + eta)(1 + rho), and the nearest row j has
    b_j <= (b_min / (1 - rho) + 2 eta)(1 + rho): every row below that limit is a candidate.
    """
    eta = 0.5 * math.sqrt(dim) * (1.0 + 1e-9) + 2.0 * _F32_UNIT_ROUNDOFF * query_code_norm
    rho = 2.0 * (dim + 3) * _F32_UNIT_ROUNDOFF
    return eta, rho


@_compiled
def screening_limit(nearest_bound: float, eta: float, rho: float) -> np.float32:
    """The largest b^2 a candidate can have when the nearest row lies at most `nearest_bound`
    from the query (in the screened values' units): the bound of `candidate_limit`, squared,
    the float32 limit rounded up, never down."""
    bound = (nearest_bound + eta) * (1.0 + rho)
    return np.float32(bound * bound * (1.0 + 1e-6))


@_compiled
def squares_of_block(
    codes: np.ndarray, b: int, size: int, query: np.ndarray, out: np.ndarray
) -> None:
    """b_i^2 of the first `size` rows of block b into out[:size] (see the module docstring)."""
    column = codes[b, 0]
    q = query[0]
    for i in range(size):
        t = np.float32(column[i]) - q
        out[i] = t * t
    for d in range(1, codes.shape[1]):
        column = codes[b, d]
        q = query[d]
        for i in range(size):
            t = np.float32(column[i]) - q
            out[i] += t * t


@_compiled
def smallest(values: np.ndarray, size: int, lanes: np.ndarray) -> np.float32:
    """The smallest of values[:size], as 16 partial minima the compiler keeps in one vector
    register (a plain running minimum of floats is not vectorised)."""
    for j in range(_LANES):
        lanes[j] = np.inf
    whole = size - size % _LANES
    for i in range(0, whole, _LANES):
        for j in range(_LANES):
            v = values[i + j]
            lanes[j] = v if v < lanes[j] else lanes[j]
    m = np.float32(np.inf)
    for j in range(_LANES):
        m = lanes[j] if lanes[j] < m else m
    for i in range(whole, size):
        m = values[i] if values[i] < m else m
    return m


@_compiled
def screen_candidates(
    codes: np.ndarray,
    n: int,
    query: np.ndarray,
    eta: float,
    rho: float,
    block_squares: np.ndarray,
    block_min: np.ndarray,
    candidates: np.ndarray,
) -> int:  # pragma: no cover - compiled; its answers are tested against brute force
    """Write the candidates' row indices, increasing, into `candidates`; return their count.

    codes (blocks, dim, BLOCK_ROWS) int8, rows 0..n-1 used (row i at [i // BLOCK_ROWS, :,
    i % BLOCK_ROWS]); query (dim,) float32 in code units; block_squares (>= BLOCK_ROWS,) and
    block_min (>= n / BLOCK_ROWS + 1,) float32 scratch; candidates (>= n,).
    """
    best = block_minima(codes, 0, n, query, block_squares, block_min)
    limit = screening_limit(math.sqrt(best) / (1.0 - rho) + eta, eta, rho)
    return block_candidates(codes, 0, n, query, limit, block_squares, block_min, candidates, 0)


@_compiled
def block_minima(
    codes: np.ndarray,
    first: int,
    n: int,
    query: np.ndarray,
    block_squares: np.ndarray,
    block_min: np.ndarray,
) -> np.float32:  # pragma: no cover - compiled
    """The smallest b^2 of rows first..n-1 (first a multiple of BLOCK_ROWS), each block's
    written into block_min (inf for none)."""
    lanes = np.empty(_LANES, np.float32)
    best = np.float32(np.inf)
    for b in range(first // BLOCK_ROWS, (n + BLOCK_ROWS - 1) // BLOCK_ROWS):
        size = min(BLOCK_ROWS, n - b * BLOCK_ROWS)
        squares_of_block(codes, b, size, query, block_squares)
        m = smallest(block_squares, size, lanes)
        block_min[b] = m
        best = m if m < best else best
    return best


@_compiled
def block_candidates(
    codes: np.ndarray,
    first: int,
    n: int,
    query: np.ndarray,
    limit: np.float32,
    block_squares: np.ndarray,
    block_min: np.ndarray,
    candidates: np.ndarray,
    count: int,
) -> int:  # pragma: no cover - compiled
    """After `block_minima`: the rows first..n-1 whose b^2 is at most `limit`, in increasing
    order, written into candidates after the `count` there; returns the new count."""
    for b in range(first // BLOCK_ROWS, (n + BLOCK_ROWS - 1) // BLOCK_ROWS):
        if block_min[b] <= limit:  # usually one block: its squares again, the same numbers
            size = min(BLOCK_ROWS, n - b * BLOCK_ROWS)
            squares_of_block(codes, b, size, query, block_squares)
            for i in range(size):
                if block_squares[i] <= limit:
                    candidates[count] = b * BLOCK_ROWS + i
                    count += 1
    return count


@compiled  # no fused operations: the codes are NumPy's rint of the same product
def store_row(rows: np.ndarray, codes: np.ndarray, n: int, row: np.ndarray, scale: float) -> bool:
    """Write `row` (dim,) as row n of `rows` (capacity, dim) and, if no |value| exceeds the
    grid's `scale`, its codes round(value * 127 / scale) into `codes` (as screen_candidates
    reads them). Returns False, codes unwritten, for a row beyond the grid (the caller widens
    the grid and re-codes every row)."""
    largest = 0.0
    for d in range(row.shape[0]):
        rows[n, d] = row[d]
        largest = max(largest, abs(row[d]))
    if largest > scale:
        return False
    factor = CODE_MAX / scale
    block, i = n // BLOCK_ROWS, n % BLOCK_ROWS
    for d in range(row.shape[0]):
        codes[block, d, i] = np.int8(np.rint(rows[n, d] * factor))
    return True
