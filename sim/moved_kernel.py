"""Which objects a movement moved, and at which step first: the numbers behind
sim/events.movement_events, compiled (numba).

Why compiled: the test runs after nearly every movement, and as eight NumPy calls on a (51, 4, 2)
array it was mostly call overhead (10 us, 4% of a kinematic iteration). The arithmetic is
NumPy's: the offset from the start, its length as the root of x*x + y*y with every operation
rounded on its own, compared with the threshold (tests/sim/test_same_numbers_faster.py holds it to
the NumPy expression).
"""

from __future__ import annotations

import numpy as np

from sim.compiled import compiled

NOT_MOVED = -1


@compiled
def first_moved_steps(
    positions: np.ndarray, threshold: float, first: np.ndarray
) -> int:  # pragma: no cover - compiled; tested against the NumPy expression
    """For each object of positions (n_rows, 1 + n_objects, 2) (column 0, the hand, is not an
    object), the first row whose offset from row 0 is longer than `threshold`, else NOT_MOVED,
    into first (n_objects,). Returns how many objects moved."""
    moved = 0
    for o in range(first.shape[0]):
        first[o] = NOT_MOVED
        x0, y0 = positions[0, 1 + o, 0], positions[0, 1 + o, 1]
        for r in range(positions.shape[0]):
            dx = positions[r, 1 + o, 0] - x0
            dy = positions[r, 1 + o, 1] - y0
            if np.sqrt(dx * dx + dy * dy) > threshold:
                first[o] = r
                moved += 1
                break
    return moved
