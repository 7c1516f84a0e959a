"""Static k-d trees over runs of a memory's rows, so that a query passes over most of them.

Why: the screen (learner/quantized_scan.py) reads every row's codes, so a query's cost grew
with the memory: 0.013 ms at a study-length trial's memories, 0.144 ms at 10^6 iterations
(docs/speed.md). The agent's memories are not spread like its queries: a model's outcomes lie near
what the arm's few joints can do, or on a few sounds, its goals anywhere in [-1, 1]^10. Cut
into leaves of rows close to one another, a memory lets a query pass over every leaf whose
bounding box lies beyond the screen's limit (docs/speed.md, "The nearest-neighbour index").

A tree covers a run of rows [first, first + size) of a memory, size a power of two times
LEAF_ROWS. The run is sorted as a k-d tree sorts it, halves split at the median of the
dimension of widest extent, down to leaves of LEAF_ROWS rows, so that FANOUT consecutive
leaves, and FANOUT consecutive groups of them, are rows close to one another. `order` lists the
run's rows leaf after leaf; the leaves hold their rows' 8-bit codes laid out as the screen's
blocks, (leaf, dim, LEAF_ROWS), so that a leaf is screened as a block is. A memory keeps both
in arrays indexed by row (the run starting at row `first` from leaf first / LEAF_ROWS on).

Above the leaves, levels of boxes: level 0 has a box per leaf (the smallest and largest code of
its rows in every dimension, in float32), level l + 1 a box per FANOUT nodes of level l, up to
a top level of FANOUT nodes or fewer. The boxes of FANOUT siblings lie together in a block,
(2, dim, FANOUT) (lo, hi), so that a node's children are weighed in one vector sweep, as a
block of rows is screened: node i of a level is lane i % FANOUT of the level's block
i // FANOUT, and its children are the lanes of block i of the level below. `levels`: each
level's first block in the memory's array of blocks, where its trees lie one after the other
(`tree_levels`).

Why codes rather than float32 rows: a query reads a sixth of a sound model's leaves at 10^6
iterations, more than the cache holds, so its cost is the bytes it reads; float32 rows took
twice the time of the full 8-bit scan. The codes' grid slack (half a step per dimension) lets
few more rows through once the bound is the exact distance of the best row found so far.

The bound that lets a node be passed over: a row's screening value is b^2 = sum_d (c_d -
q_d)^2 in float32 (quantized_scan). For a row inside a box [lo, hi], |c_d - q_d| >= g_d =
max(0, lo_d - q_d, q_d - hi_d) also after rounding (rounding is monotonic), so the box's sum
of g_d^2 (`weigh_block`) is at most b^2 but for the float32 error of the two sums, (dim + 2) u
each, whatever their order, which the screen's `rho` covers twice over: a node whose box value
times (1 - rho) exceeds the screen's limit holds no candidate.
"""

from __future__ import annotations

import math

import numpy as np

from learner.compiled import compiled
from learner.quantized_scan import screening_limit, smallest, squares_of_block

LEAF_ROWS = 64  # rows per leaf: four vectors of 16 float32 lanes
FANOUT = 16  # nodes per block of boxes: one vector of 16 float32 lanes
EXACT_MARGIN = 1e-10  # over a float64 distance's relative rounding error (about 1e-15)
_STACK = 1024  # nodes waiting in a search: FANOUT per level at most, and 64 levels
_LANES = 16


def tree_levels(leaves: int) -> list[int]:
    """The first block of each level of a tree of `leaves` leaves, from the leaves up, and the
    number of its blocks, last."""
    starts, nodes = [0], leaves
    while True:
        blocks = -(-nodes // FANOUT)
        starts.append(starts[-1] + blocks)
        if blocks == 1:
            return starts
        nodes = blocks


@compiled
def build_tree(
    rows: np.ndarray,
    codes: np.ndarray,
    first: int,
    size: int,
    order: np.ndarray,
    leaf_codes: np.ndarray,
    boxes: np.ndarray,
    levels: np.ndarray,
) -> None:  # pragma: no cover - compiled; the trees' answers are tested against brute force
    """Sort the rows [first, first + size) of `rows` (float64, a row each; their codes in the
    screen's blocks `codes`) into a tree: writes order[first : first + size], their leaves'
    codes and the tree's blocks of boxes, (blocks, 2, dim, FANOUT), at the levels' first
    blocks `levels` (module docstring)."""
    block_rows = codes.shape[2]
    dim = rows.shape[1]
    local = np.arange(size)
    values = np.empty(size)
    part = size
    while part > LEAF_ROWS:  # one level of the k-d tree at a time: every node of it split
        for start in range(0, size, part):
            segment = local[start : start + part]
            widest, extent = 0, -1.0
            for d in range(dim):
                low = high = rows[first + segment[0], d]
                for i in segment:
                    low = min(low, rows[first + i, d])
                    high = max(high, rows[first + i, d])
                if high - low > extent:
                    widest, extent = d, high - low
            for j in range(part):
                values[j] = rows[first + segment[j], widest]
            segment[:] = segment[np.argsort(values[:part], kind="mergesort")]
        part //= 2
    leaves, first_leaf = size // LEAF_ROWS, first // LEAF_ROWS
    tree_boxes = boxes[levels[0] : levels[-1]]
    tree_boxes[:, 0] = np.inf  # lanes past a level's last node: boxes no query comes near
    tree_boxes[:, 1] = -np.inf
    for leaf in range(leaves):
        block, lane = levels[0] + leaf // FANOUT, leaf % FANOUT
        for i in range(LEAF_ROWS):
            row = first + local[leaf * LEAF_ROWS + i]
            order[first + leaf * LEAF_ROWS + i] = row
            leaf_codes[first_leaf + leaf, :, i] = codes[row // block_rows, :, row % block_rows]
        for d in range(dim):
            boxes[block, 0, d, lane] = leaf_codes[first_leaf + leaf, d].min()
            boxes[block, 1, d, lane] = leaf_codes[first_leaf + leaf, d].max()
    for level in range(1, len(levels) - 1):  # each node the box of its block below
        for i in range(levels[level] - levels[level - 1]):
            below = levels[level - 1] + i
            block, lane = levels[level] + i // FANOUT, i % FANOUT
            for d in range(dim):
                boxes[block, 0, d, lane] = boxes[below, 0, d].min()
                boxes[block, 1, d, lane] = boxes[below, 1, d].max()


@compiled
def distance(rows: np.ndarray, i: int, q: np.ndarray) -> float:  # pragma: no cover - compiled
    """Euclidean distance from rows[i] to q, float64."""
    square = 0.0
    for d in range(q.shape[0]):
        t = rows[i, d] - q[d]
        square += t * t
    return math.sqrt(square)


def _weigh_block(boxes: np.ndarray, block: int, query: np.ndarray, out: np.ndarray) -> None:
    """out[j]: the sum of g_d^2 (module docstring) of lane j's box of `block`, in float32."""
    lo, hi = boxes[block, 0], boxes[block, 1]
    for j in range(FANOUT):
        out[j] = 0.0
    for d in range(query.shape[0]):
        q = query[d]
        for j in range(FANOUT):
            g = max(max(lo[d, j] - q, q - hi[d, j]), np.float32(0.0))
            out[j] += g * g


# Multiply-adds fused, as in the screen's sums (the bound allows either).
weigh_block = compiled(_weigh_block, contract=True)


@compiled
def search_tree(
    tree: tuple,
    q: np.ndarray,
    query: np.ndarray,
    code_scale: float,
    eta: float,
    rho: float,
    nearest: float,
    scratch: tuple,
    recorded: int,
) -> tuple[float, int]:  # pragma: no cover - compiled
    """One tree's screen: depth first, nearer nodes first, every node whose box can hold a row
    under the limit of `nearest`, an upper bound of the nearest row's distance in code units
    that each leaf lowers (by the exact distance of its best row). tree: (first, levels, boxes,
    order, leaf_codes, rows); q (dim,) the float64 query, query its codes (float32), code_scale
    a code per row unit; eta, rho: candidate_limit's. Records each leaf row under the limit
    (row index, b^2) in scratch's candidates after the `recorded` ones; returns the new bound
    and count."""
    first, levels, boxes, order, leaf_codes, rows = tree
    block_squares, _, candidates, candidate_squares = scratch
    first_leaf = first // LEAF_ROWS
    shrink = 1.0 - rho  # the margin for the box's and the rows' rounding
    limit = screening_limit(nearest, eta, rho) if nearest < np.inf else np.float32(np.inf)
    lanes = np.empty(_LANES, np.float32)
    # The nodes waiting (level, node, box value) and the scratch their blocks are weighed in.
    stack = (
        np.empty(_STACK, np.int64),
        np.empty(_STACK, np.int64),
        np.empty(_STACK, np.float32),
        np.empty(FANOUT, np.float32),
    )
    stack_level, stack_node, stack_value, _ = stack
    top = _push_block(levels.shape[0] - 2, 0, boxes, levels, query, limit, shrink, stack, 0)
    while top > 0:
        top -= 1
        level, node = stack_level[top], stack_node[top]
        if stack_value[top] * shrink > limit:
            continue
        if level > 0:
            top = _push_block(level - 1, node, boxes, levels, query, limit, shrink, stack, top)
            continue
        leaf = first_leaf + node
        squares_of_block(leaf_codes, leaf, LEAF_ROWS, query, block_squares)
        least = smallest(block_squares, LEAF_ROWS, lanes)
        if least > limit:
            continue
        if math.sqrt(least) / (1.0 - rho) + eta < nearest:  # a row nearer than any so far
            for i in range(LEAF_ROWS):
                if block_squares[i] == least:
                    exact = distance(rows, order[leaf * LEAF_ROWS + i], q) * code_scale
                    nearest = min(nearest, exact * (1.0 + EXACT_MARGIN))
            limit = screening_limit(nearest, eta, rho)
        for i in range(LEAF_ROWS):
            if block_squares[i] <= limit:
                candidates[recorded] = order[leaf * LEAF_ROWS + i]
                candidate_squares[recorded] = block_squares[i]
                recorded += 1
    return nearest, recorded


@compiled
def _push_block(
    level: int,
    block: int,
    boxes: np.ndarray,
    levels: np.ndarray,
    query: np.ndarray,
    limit: np.float32,
    shrink: float,
    stack: tuple,
    top: int,
) -> int:  # pragma: no cover - compiled
    """Weigh the nodes of `block` of `level` and push those under the limit onto `stack`
    (search_tree's), nearest last (on top); returns the new top."""
    stack_level, stack_node, stack_value, weights = stack
    weigh_block(boxes, levels[level] + block, query, weights)
    start = top
    for j in range(FANOUT):
        value = weights[j]
        if value * shrink > limit or not value < np.inf:  # or a lane past the last node
            continue
        k = top  # insertion: the stack's new part kept in decreasing value
        while k > start and stack_value[k - 1] < value:
            stack_level[k], stack_node[k], stack_value[k] = (
                stack_level[k - 1],
                stack_node[k - 1],
                stack_value[k - 1],
            )
            k -= 1
        stack_level[k], stack_node[k], stack_value[k] = level, block * FANOUT + j, value
        top += 1
    return top
