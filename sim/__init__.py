"""The playroom world: MuJoCo physics, DMPs, grasp rules, caregiver, vocal tract, dm_control task.

`sim` knows nothing of learning, and importing it leaves the process environment alone: which
OpenGL backend MuJoCo loads is the caller's choice (`MUJOCO_GL`, see experiments/video/gl.py).
`Playroom` and `Feedback` are loaded on first use, so that `sim.config` and the other plain
modules can be imported without MuJoCo.

MuJoCo loads the GL library `MUJOCO_GL` names when it is first imported, and PyOpenGL reports
one that cannot be loaded (an empty or broken libEGL.so.1, as on many cluster nodes) as
"'NoneType' object has no attribute 'eglQueryString'" deep in its own modules. So while such a
name is set and mujoco is not yet imported, the first import of mujoco checks the library first
and fails in one line (`gl_library_problem`) that says how to go on; nothing is checked, and no
library loaded, before something imports mujoco.
"""

from __future__ import annotations

import ctypes
import os
import sys
from collections.abc import Iterator, Sequence
from contextlib import contextmanager
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from importlib.machinery import ModuleSpec
    from types import ModuleType

    from sim.playroom import Feedback, Playroom

__all__ = ["Feedback", "Playroom", "environment_kept", "gl_library_problem"]

GL_VARIABLE = "MUJOCO_GL"
# The backends whose system library PyOpenGL loads (by its ctypes name), with how to get it and
# the other backend to try; GLFW's wheel carries its own library.
GL_LIBRARIES = {
    "egl": ("EGL", "libegl1 on Debian/Ubuntu, mesa-libEGL on Fedora", "osmesa"),
    "osmesa": ("OSMesa", "libosmesa6 on Debian/Ubuntu, mesa-libOSMesa on Fedora", "egl"),
}


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


# threadpoolctl, which scipy.io imports (sim/vocal/audio.py reads and writes WAV files with it),
# sets KMP_DUPLICATE_LIB_OK=True when imported: with torch beside the room, that would hide two
# OpenMP runtimes in one process. It is imported here first, once, and the variable put back;
# a later import of it sets nothing (Python imports a module once).
with environment_kept():
    import threadpoolctl  # noqa: F401


def _library_names(name: str) -> list[str]:
    # The file names PyOpenGL tries, in its order (OpenGL/platform/ctypesloader.py).
    return [f"lib{name}.so", *(f"lib{name}.so.{i}" for i in reversed(range(10)))]


def gl_library_problem(backend: str) -> str | None:
    """One line saying that the system library of `backend` (MUJOCO_GL's value) cannot be
    loaded and how to go on; None if it loads, or if the backend needs no system library."""
    backend = backend.strip().lower()
    if backend not in GL_LIBRARIES:
        return None
    name, packages, other = GL_LIBRARIES[backend]
    errors = []
    for file_name in _library_names(name):
        try:
            ctypes.CDLL(file_name, mode=ctypes.RTLD_GLOBAL)
            return None
        except OSError as exc:
            errors.append(str(exc))
    # A file that exists but is broken says more than the names that are absent.
    found = [e for e in errors if "No such file" not in e and "cannot open" not in e]
    reason = found[0] if found else f"no lib{name}.so* found"
    return (
        f"{GL_VARIABLE}={backend} but the {name} library cannot be loaded ({reason}); unset "
        f"{GL_VARIABLE} for commands that do not render, or install lib{name} ({packages}) or "
        f"use {GL_VARIABLE}={other}"
    )


class _GLLibraryCheck:
    """A finder that runs before mujoco's first import (see the module's docstring): it raises
    ImportError with `gl_library_problem`'s line, or steps aside once the library loads."""

    def find_spec(
        self, fullname: str, path: Sequence[str] | None, target: ModuleType | None = None
    ) -> ModuleSpec | None:
        if fullname != "mujoco":
            return None
        problem = gl_library_problem(os.environ.get(GL_VARIABLE, ""))
        if problem is not None:
            raise ImportError(problem)
        if self in sys.meta_path:
            sys.meta_path.remove(self)
        return None


if "mujoco" not in sys.modules and os.environ.get(GL_VARIABLE, "").strip().lower() in GL_LIBRARIES:
    sys.meta_path.insert(0, _GLLibraryCheck())


def __getattr__(name: str) -> Any:
    if name in ("Feedback", "Playroom"):
        try:
            from sim import playroom
        except AttributeError as exc:
            # An AttributeError raised here would read as "cannot import name 'Playroom'",
            # hiding what failed while the room's modules were imported.
            raise ImportError(f"importing sim.playroom failed: {exc}") from exc
        return getattr(playroom, name)
    raise AttributeError(f"module 'sim' has no attribute {name!r}")
