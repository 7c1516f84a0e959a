"""What the room accepts as a command or a placement: finite numbers of the right shape, commands
in [-1, 1]; anything else is refused with a ValueError naming what is wrong."""

from __future__ import annotations

import numpy as np

# Commands may exceed [-1, 1] by this much (float round-off) before they are refused.
RANGE_TOLERANCE = 1e-9


def checked_array(value, shape: tuple[int, ...], what: str) -> np.ndarray:
    """`value` as a finite float array of `shape`, or ValueError naming what is wrong."""
    try:
        arr = np.asarray(value, dtype=float)
    except (TypeError, ValueError) as exc:
        raise ValueError(f"{what} must be numbers: {exc}") from None
    if arr.shape != shape:
        raise ValueError(f"{what} must have shape {shape}, got {arr.shape}")
    if not np.logical_and.reduce(np.isfinite(arr), axis=None):  # .all(), without its wrapper
        bad = np.flatnonzero(~np.isfinite(arr.ravel()))
        raise ValueError(f"{what} contains NaN or inf at flat indices {bad.tolist()}")
    return arr


def checked_command(m, dim: int, what: str) -> np.ndarray:
    """The command as a float array of shape (dim,) in [-1, 1], or ValueError naming what is
    wrong."""
    arr = checked_array(m, (dim,), what)
    if np.maximum.reduce(np.abs(arr)) > 1.0 + RANGE_TOLERANCE:  # .max(), without its wrapper
        raise ValueError(f"{what} must lie in [-1, 1], max |value| is {np.abs(arr).max():.6g}")
    return np.minimum(np.maximum(arr, -1.0), 1.0)  # np.clip's values, without its wrapper
