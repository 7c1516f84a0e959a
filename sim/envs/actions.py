"""The one check of commands that both environments of sim/envs/ make, before anything moves:
real, finite numbers of the right shape in [-1, 1], the command not chosen included (when it is
given: the dm_env action may leave it out). Refusals are one-line ValueErrors that give the
offending values exactly (their repr) and a few of their indices."""

from __future__ import annotations

import numpy as np

from sim.commands import RANGE_TOLERANCE

# How many offending indices a message names before "and N more".
SHOWN = 5
# Array kinds that are real numbers: signed and unsigned integers, floats. Booleans, complex
# numbers, strings and objects are refused rather than converted (NumPy would turn True into
# 1.0 and drop an imaginary part with only a warning).
REAL_KINDS = "iuf"


def _few(indices: np.ndarray, values: np.ndarray) -> str:
    """The first SHOWN indices with their values, exactly: "[3 (-1.0000001), ...] and N more"."""
    shown = ", ".join(f"{int(i)} ({float(values[i])!r})" for i in indices[:SHOWN])
    more = f" and {indices.size - SHOWN} more" if indices.size > SHOWN else ""
    return f"[{shown}]{more}"


def checked_numbers(value: object, size: int, what: str) -> np.ndarray:
    """`value` as a new float64 array of shape (size,) in [-1, 1] (within float round-off,
    RANGE_TOLERANCE, then clipped), or ValueError in one line naming what is wrong."""
    try:
        array = np.asarray(value)
    except (TypeError, ValueError) as exc:  # ragged nested sequences
        raise ValueError(f"{what} must be {size} real numbers in [-1, 1]: {exc}") from None
    if array.dtype.kind not in REAL_KINDS:
        got = type(value).__name__ if array.ndim == 0 else f"an array of {array.dtype}"
        raise ValueError(f"{what} must be {size} real numbers in [-1, 1], got {got}")
    if array.shape != (size,):
        raise ValueError(f"{what} must have shape ({size},), got {array.shape}")
    numbers = array.astype(np.float64)
    not_finite = np.flatnonzero(~np.isfinite(numbers))
    if not_finite.size:
        raise ValueError(f"{what} contains NaN or inf at indices {_few(not_finite, numbers)}")
    outside = np.flatnonzero(np.abs(numbers) > 1.0 + RANGE_TOLERANCE)
    if outside.size:
        raise ValueError(f"{what} must lie in [-1, 1], outside at indices {_few(outside, numbers)}")
    return np.clip(numbers, -1.0, 1.0)
