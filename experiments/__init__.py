"""Experiments: the command line, trials, evaluation, batches, reports, videos, bench.

MuJoCo picks its OpenGL backend when it is first imported, so the project's offscreen default
(EGL, which also works without a GPU through Mesa) is set here, before any module imports it.
Set MUJOCO_GL=osmesa in the environment to use OSMesa instead.
"""

import os

os.environ.setdefault("MUJOCO_GL", "egl")
