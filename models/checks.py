"""Checks of single settings, shared by the world's, the voice's and the learner's configs
(sim/config.py, sim/vocal/config.py, learner/config.py), which cannot import each other.

Each check raises ValueError with one line naming the setting, what it allows and what it got.
Values come from JSON as often as from Python, so types are checked, never coerced: a string
is not a number, a bool is not an integer, and 2.0 is not an integer either. Numbers must be
finite: NaN compares false with every bound and would slip through a range check.
"""

from __future__ import annotations

import math
import numbers
from typing import Any


def is_number(value: Any) -> bool:
    """A finite real number that is not a bool (NumPy scalars included)."""
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        return False
    try:
        return math.isfinite(value)
    except OverflowError:  # an int too large for a float
        return False


def _got(value: Any) -> str:
    """A bad value as shown in a message: its repr (a string keeps its quotes), shortened."""
    shown = repr(value)
    return shown if len(shown) <= 60 else shown[:57] + "..."


def _range(interval: str) -> str:
    """ " > 0" for "(0, inf)", " >= 0" for "[0, inf)", " in (0, 1]" otherwise."""
    if interval == "(-inf, inf)":
        return ""
    low, high = (part.strip() for part in interval[1:-1].split(","))
    if high == "inf":
        return f" {'>' if interval[0] == '(' else '>='} {low}"
    return f" in {interval}"


def _inside(value: float, interval: str) -> bool:
    low_bracket, high_bracket = interval[0], interval[-1]
    low, high = (float(part) for part in interval[1:-1].split(","))
    above = value > low if low_bracket == "(" else value >= low
    below = value < high if high_bracket == ")" else value <= high
    return above and below


def check_number(name: str, value: Any, interval: str = "(-inf, inf)") -> None:
    """`value` is a finite number in `interval`, written as in mathematics: "(0, 1]", "[0, inf)"."""
    if not (is_number(value) and _inside(float(value), interval)):
        raise ValueError(f"{name} must be a finite number{_range(interval)}, got {_got(value)}")


def check_numbers(name: str, value: Any, length: int, interval: str = "(-inf, inf)") -> None:
    """`value` is a list or tuple of exactly `length` finite numbers, each in `interval`."""
    ok = isinstance(value, list | tuple) and len(value) == length
    if not (ok and all(is_number(v) and _inside(float(v), interval) for v in value)):
        raise ValueError(
            f"{name} must be {length} finite numbers{_range(interval)}, got {_got(value)}"
        )


# The largest integer an int64 holds: a trial's logs and checkpoints keep their integers
# (iterations, counts) in int64, so no period or count of a trial can need more.
INT64_MAX = 2**63 - 1


def check_int(name: str, value: Any, minimum: int = 1, maximum: int | None = None) -> None:
    """`value` is an integer (not a bool, not a float) >= `minimum` and, given one, <= `maximum`
    (a size that must fit memory, a count that must fit an int64)."""
    integer = not isinstance(value, bool) and isinstance(value, numbers.Integral)
    if not (integer and value >= minimum and (maximum is None or value <= maximum)):
        shown = "2**63 - 1" if maximum == INT64_MAX else str(maximum)
        allowed = f">= {minimum}" if maximum is None else f"in [{minimum}, {shown}]"
        raise ValueError(f"{name} must be an integer {allowed}, got {_got(value)}")


def check_choice(name: str, value: Any, choices: tuple[str, ...]) -> None:
    """`value` is one of the strings `choices`, spelled exactly (case included)."""
    if not (isinstance(value, str) and value in choices):
        allowed = ", ".join(repr(c) for c in choices)
        raise ValueError(f"{name} must be one of {allowed}, got {_got(value)}")


def check_bool(name: str, value: Any) -> None:
    """`value` is true or false (not 0 or 1, not a string)."""
    if not isinstance(value, bool):
        raise ValueError(f"{name} must be true or false, got {_got(value)}")


def tuples(value: Any) -> Any:
    """Lists (as JSON gives them) as tuples, nested: configs stay hashable and compare equal
    to their defaults."""
    if isinstance(value, list | tuple):
        return tuple(tuples(v) for v in value)
    return value


# The largest seed of a trial or batch: every log row records its seed in an int64 Parquet
# column (experiments/analysis/logs.py), which holds no more. NumPy's generators take any
# non-negative integer, and nothing derives a seed from a trial's (seed * K + i), so the
# column is the only bound; seeds up to it ran, were evaluated and reported.
MAX_SEED = 2**63 - 1


def check_seed(name: str, value: Any) -> None:
    """`value` is an integer seed (not a bool, not a float) in [0, MAX_SEED]."""
    if isinstance(value, bool) or not isinstance(value, numbers.Integral):
        raise ValueError(f"{name} must be an integer in [0, 2**63 - 1], got {_got(value)}")
    if not 0 <= int(value) <= MAX_SEED:
        raise ValueError(f"{name} must be an integer in [0, 2**63 - 1], got {_got(value)}")
