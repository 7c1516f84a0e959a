"""Whether the OpenGL library `MUJOCO_GL` names can be loaded, said in one line.

MuJoCo loads the GL library `MUJOCO_GL` names when it is first imported, and PyOpenGL reports
one that cannot be loaded (an empty or broken libEGL.so.1, as on many cluster nodes) as
"'NoneType' object has no attribute 'eglQueryString'" deep in its own modules.
`gl_library_problem` says instead what is wrong and how to go on; the project's one import of
mujoco (sim/mujoco_import.py) asks it first, and so do the renderers (sim/envs/rendering.py,
experiments/video/gl.py).
"""

from __future__ import annotations

import ctypes

__all__ = ["GL_LIBRARIES", "GL_VARIABLE", "gl_library_problem"]

GL_VARIABLE = "MUJOCO_GL"
# The backends whose system library PyOpenGL loads (by its ctypes name), with how to get it and
# the other backend to try; GLFW's wheel carries its own library.
GL_LIBRARIES = {
    "egl": ("EGL", "libegl1 on Debian/Ubuntu, mesa-libEGL on Fedora", "osmesa"),
    "osmesa": ("OSMesa", "libosmesa6 on Debian/Ubuntu, mesa-libOSMesa on Fedora", "egl"),
}


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
