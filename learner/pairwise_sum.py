"""NumPy's sum of up to 128 contiguous float64 values, compiled (numba), to the last bit.

`np.add.reduce` of a contiguous vector adds in a fixed order, NumPy's pairwise summation: under
8 values one after the other; up to 128 (one block) in 8 running sums (value i into sum i mod
8) combined as ((s0 + s1) + (s2 + s3)) + ((s4 + s5) + (s6 + s7)), the values beyond the last
multiple of 8 then added one by one; all of it added to the reduction's identity, 0.0. (Beyond
128 values NumPy sums the two halves recursively: not compiled here, where recursive functions
loaded from numba's cache crashed.) Compiled code that adds in this order gives NumPy's sums
where a NumPy call would cost more than the sum (tests/learner/test_pairwise_sum.py holds it to
`np.add.reduce` for every length, natively and without AVX-512).
"""

from __future__ import annotations

import numpy as np

from learner.compiled import compiled

BLOCK = 128  # NumPy's PW_BLOCKSIZE: the longest sum computed here
_LANES = 8  # its running sums


@compiled
def pairwise_sum(values: np.ndarray, start: int, n: int) -> float:  # pragma: no cover - compiled
    """np.add.reduce(values[start:start + n]) for a contiguous float64 `values`, n <= BLOCK."""
    if n > BLOCK:
        raise ValueError("pairwise_sum sums at most BLOCK values")
    if n < _LANES:
        total = -0.0
        for i in range(start, start + n):
            total += values[i]
        return 0.0 + total
    sums = values[start : start + _LANES].copy()
    whole = n - n % _LANES
    for i in range(_LANES, whole, _LANES):
        for j in range(_LANES):
            sums[j] += values[start + i + j]
    total = ((sums[0] + sums[1]) + (sums[2] + sums[3])) + (
        (sums[4] + sums[5]) + (sums[6] + sums[7])
    )
    for i in range(start + whole, start + n):
        total += values[i]
    return 0.0 + total
