"""How the learner compiles its numeric kernels (numba), as the world does in sim/compiled.py
(the world and the learner import nothing of each other).

numba checks a cached kernel against its own source file only: a kernel that calls kernels of
another file (the memory's screen calls the trees' search and the scan's sums) would keep a
stale copy of them after that file changed, as after a `git checkout`, and read arrays laid out
otherwise (with bounds unchecked: wrong answers or a crash). So whenever any source file of the
learner changes, its cached kernels are dropped once and compiled again (`forget_stale_kernels`).
"""

from __future__ import annotations

import hashlib
from collections.abc import Callable
from pathlib import Path
from typing import Any, TypeVar

import numba

F = TypeVar("F", bound=Callable[..., Any])
KERNEL_STAMP = "kernels.sha256"  # the digest of the sources the cached kernels were built from


def forget_stale_kernels(package: Path) -> bool:
    """Delete numba's cached kernels in `package`'s __pycache__ if its .py files changed since
    they were cached (a digest of their bytes, kept beside them); True if it deleted them. A
    folder that cannot be written is left alone: numba caches elsewhere, or not at all."""
    sources = sorted(package.glob("*.py"))
    digest = hashlib.sha256(b"".join(p.name.encode() + p.read_bytes() for p in sources))
    cache, stamp = package / "__pycache__", package / "__pycache__" / KERNEL_STAMP
    try:
        if stamp.read_text() == digest.hexdigest():
            return False
    except OSError:
        pass  # no stamp yet
    try:
        cache.mkdir(exist_ok=True)
        for kernel in [*cache.glob("*.nbi"), *cache.glob("*.nbc")]:
            kernel.unlink(missing_ok=True)
        stamp.write_text(digest.hexdigest())
    except OSError:
        return False
    return True


forget_stale_kernels(Path(__file__).parent)


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
