"""How the learner compiles its numeric kernels (numba), as the world does in sim/compiled.py
(the world and the learner import nothing of each other)."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any, TypeVar

import numba

F = TypeVar("F", bound=Callable[..., Any])


def compiled(function: F, contract: bool = False) -> F:
    """`function` compiled by numba, cached on disk beside the package (or in the user's
    cache) so that later processes load it in 0.2 s. Where no cache directory is writable (a
    read-only install without a home directory) numba refuses to cache: it is then compiled
    once per process instead, about 1 s.

    Without `contract`, every operation rounds on its own, as NumPy's do, so a kernel written
    in NumPy's order of operations gives NumPy's numbers to the last bit. `contract` lets the
    compiler fuse a multiply and an add (the memory's screening, whose error bound allows it).
    """
    options: dict[str, Any] = {"nogil": True, "boundscheck": False}
    if contract:
        options["fastmath"] = {"contract"}
    try:
        return numba.njit(cache=True, **options)(function)
    except RuntimeError:
        return numba.njit(**options)(function)
