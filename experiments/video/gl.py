"""Which OpenGL backend MuJoCo loads, chosen by the command being run, never at import.

MuJoCo (and dm_control) read `MUJOCO_GL` once, when first imported, and load that GL library
then: with it unset they load GLFW, with `egl` PyOpenGL's EGL, which fails on machines whose
libEGL cannot be loaded (most cluster nodes). So the `playroom` command decides before anything
imports mujoco: commands that render ask for a backend (EGL unless the user chose another),
every other command asks for none, so `run`, `eval`, `batch`, `report` and `compare` work on a
machine without any GL library. A user's own `MUJOCO_GL` is always respected: one that names a
library that cannot be loaded stops every command in one line saying so.
"""

from __future__ import annotations

import os
import sys

VARIABLE = "MUJOCO_GL"
# Offscreen backends MuJoCo can render with; EGL works with an NVIDIA driver or Mesa.
RENDER_BACKENDS = ("egl", "osmesa", "glfw")
DEFAULT_RENDER_BACKEND = "egl"
# The value under which MuJoCo and dm_control load no GL library at all.
NO_BACKEND = "disable"
# The system library PyOpenGL loads for a backend (its ctypes name) and the packages that
# provide it: a backend whose library is absent is named in one line, not as PyOpenGL's
# "'NoneType' object has no attribute 'glGetError'". GLFW's wheel carries its own library.
SYSTEM_LIBRARIES = {
    "egl": ("EGL", "libegl1 (Debian/Ubuntu) or mesa-libEGL (Fedora)"),
    "osmesa": ("OSMesa", "libosmesa6 (Debian/Ubuntu) or mesa-libOSMesa (Fedora)"),
}


class GLError(Exception):
    """No usable OpenGL backend for rendering; the message names MUJOCO_GL and its choices."""


def choices() -> str:
    """What a user can set, for error messages."""
    return f"set {VARIABLE} to one of {', '.join(RENDER_BACKENDS)}"


def without_rendering() -> None:
    """For commands that never render: load no GL library (unless the user chose one); GLError
    in one line if the user's choice names a library that cannot be loaded, which mujoco's
    import would otherwise fail on."""
    if "mujoco" not in sys.modules:
        os.environ.setdefault(VARIABLE, NO_BACKEND)
        unloadable = unloadable_library(os.environ[VARIABLE])
        if unloadable is not None:
            raise GLError(unloadable)


def unloadable_library(backend: str) -> str | None:
    """The one-line message for a backend whose system library is there but cannot be loaded
    (an empty or broken libEGL.so.1 on a cluster node), else None: sim's check, which the first
    import of mujoco runs too (sim/mujoco_import.py)."""
    from sim import gl_library_problem

    return gl_library_problem(backend)


def for_viewing() -> None:
    """For the interactive viewer (`playroom view`): GLFW, which opens windows; GLError if the
    user chose another backend or mujoco was imported with one."""
    chosen = os.environ.setdefault(VARIABLE, "glfw").strip().lower()
    if chosen != "glfw":
        raise GLError(f"the viewer opens a window with GLFW: unset {VARIABLE} (it is {chosen!r})")
    if "mujoco" in sys.modules:
        from sim.mujoco_import import mujoco

        loaded = getattr(getattr(mujoco, "GLContext", None), "__module__", "none")
        if loaded.split(".")[-1] != "glfw":
            raise GLError(f"mujoco was imported with another OpenGL backend ({loaded})")


def missing_library(backend: str) -> str | None:
    """The one-line message for a backend whose system library cannot be found, else None."""
    import ctypes.util

    if backend not in SYSTEM_LIBRARIES:
        return None
    name, packages = SYSTEM_LIBRARIES[backend]
    if ctypes.util.find_library(name) is not None:
        return None
    return (
        f"lib{name} not found ({VARIABLE}={backend}): install the system package {packages}, "
        f"or {choices()}"
    )


def for_rendering() -> str:
    """For commands that render: choose the backend (EGL by default), load it, and return its
    name; GLError in one line if it cannot be loaded."""
    chosen = os.environ.setdefault(VARIABLE, DEFAULT_RENDER_BACKEND).strip().lower()
    if chosen not in RENDER_BACKENDS:
        raise GLError(f"{VARIABLE}={chosen!r} cannot render: {choices()}")
    missing = missing_library(chosen) or unloadable_library(chosen)
    if missing is not None:
        raise GLError(missing)
    try:
        from sim.mujoco_import import mujoco

        context_class = getattr(mujoco, "GLContext", None)
        if context_class is None:
            raise ImportError("mujoco loaded no GL context")
        loaded = context_class.__module__.split(".")[-1]
        if loaded != chosen:
            raise GLError(
                f"mujoco was imported before rendering was set up and uses {loaded}, not "
                f"{VARIABLE}={chosen}; set {VARIABLE} before starting Python ({choices()})"
            )
        # A context of one pixel: a driver that loads but cannot render fails here, in one line,
        # rather than deep inside the first frame.
        context_class(1, 1).free()
    except GLError:
        raise
    except Exception as exc:  # PyOpenGL raises AttributeError, OSError, ImportError, ...
        raise GLError(
            f"the OpenGL backend {VARIABLE}={chosen} cannot be loaded "
            f"({type(exc).__name__}: {exc}); {choices()}"
        ) from None
    return chosen
