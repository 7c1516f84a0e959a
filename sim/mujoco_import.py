"""MuJoCo, imported for the whole project here and only here, after checking the GL library.

MuJoCo loads the GL library `MUJOCO_GL` names at its first import; where that library cannot
be loaded, the import fails deep in PyOpenGL. So while such a name is set and mujoco is not yet
imported, the library is checked first and a failure is one line that says how to go on
(`gl_library_problem`, ImportError). Nothing is checked, and no library loaded, before
something imports mujoco; every module of the project that uses MuJoCo imports it from here
(`from sim.mujoco_import import mujoco`), dm_control's import too (sim/dm_control_import.py).
"""

from __future__ import annotations

import os
import sys

from sim.gl_library import GL_VARIABLE, gl_library_problem

if "mujoco" not in sys.modules:
    _problem = gl_library_problem(os.environ.get(GL_VARIABLE, ""))
    if _problem is not None:
        raise ImportError(_problem)

import mujoco  # noqa: E402 (after the check: its import loads the GL library)

__all__ = ["mujoco"]
