"""The process environment, left as it was: importing the project changes no variable.

`environment_kept` puts the environment back after a block, for third-party imports that set
variables. threadpoolctl, which scipy.io imports (sim/vocal/audio.py reads and writes WAV files
with it), sets KMP_DUPLICATE_LIB_OK=True when imported: with torch beside the room, that would
hide two OpenMP runtimes in one process. It is imported here first, once (the `sim` package
imports this module), and the variable put back; a later import of it sets nothing (Python
imports a module once).
"""

from __future__ import annotations

import os
from collections.abc import Iterator
from contextlib import contextmanager

__all__ = ["environment_kept"]


@contextmanager
def environment_kept() -> Iterator[None]:
    """Puts the process environment back as it was after the block: for third-party imports
    that set variables (importing this project's packages changes none)."""
    saved = dict(os.environ)
    try:
        yield
    finally:
        for name in set(os.environ) - set(saved):
            del os.environ[name]
        for name, value in saved.items():
            if os.environ.get(name) != value:
                os.environ[name] = value


with environment_kept():
    import threadpoolctl  # noqa: F401
