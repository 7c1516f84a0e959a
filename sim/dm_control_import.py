"""dm_control, imported once for the package without GLFW's complaint on a headless machine.

With `MUJOCO_GL` unset, importing `dm_control.mujoco` picks an OpenGL backend at once and tries
GLFW first, whose `glfw.init()` warns "The DISPLAY environment variable is missing" on any
machine without a display, although nothing renders. The choice itself is left as it is
(rendering is the caller's, experiments/video/gl.py); only the warnings of that import are not
shown. A real rendering failure still raises when a context is made.
"""

from __future__ import annotations

import warnings

with warnings.catch_warnings():
    # glfw reports its errors as warnings from its own module (glfw.GLFWError).
    warnings.filterwarnings("ignore", module="glfw")
    from dm_control import mujoco as dm_mujoco
    from dm_control.rl import control

__all__ = ["control", "dm_mujoco"]
