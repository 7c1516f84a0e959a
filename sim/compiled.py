"""How the world compiles its numeric kernels (numba). Imported only by the modules that hold a
kernel, when first used: building the command line or reading results loads no compiler
(tests/test_layers.py). The learner compiles its memory's kernel alike
(learner/quantized_scan.py; the world and the learner import nothing of each other)."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any, TypeVar

import numba

F = TypeVar("F", bound=Callable[..., Any])


def compiled(function: F) -> F:
    """`function` compiled by numba, cached on disk beside the package (or in the user's
    cache) so that later processes load it in a fraction of a second. Where no cache directory
    is writable (a read-only install without a home directory) numba refuses to cache: it is
    then compiled once per process instead, about a second.

    No fast-math: every operation rounds on its own, as NumPy's do, so a kernel written in
    NumPy's order of operations gives NumPy's numbers to the last bit.
    """
    options: dict[str, Any] = {"nogil": True, "boundscheck": False}
    try:
        return numba.njit(cache=True, **options)(function)
    except RuntimeError:
        return numba.njit(**options)(function)
