"""Shared test setup.

MuJoCo picks its OpenGL backend when `mujoco` is first imported, and some test modules import
it before `sim` (which sets the project's EGL default): set the default here, first.
"""

import os

os.environ.setdefault("MUJOCO_GL", "egl")
