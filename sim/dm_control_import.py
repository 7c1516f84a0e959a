"""dm_control, imported once for the package without GLFW's complaint on a headless machine, and
without a broken EGL library stopping a room that never renders.

With `MUJOCO_GL` unset, importing `dm_control.mujoco` picks an OpenGL backend at once and tries
GLFW first, whose `glfw.init()` warns "The DISPLAY environment variable is missing" on any
machine without a display, although nothing renders. The choice itself is left as it is
(rendering is the caller's, experiments/video/gl.py); only the warnings of that import are not
shown. A real rendering failure still raises when a context is made.

Where GLFW cannot be imported, dm_control goes on to EGL and OSMesa, passing over only an
ImportError; a libEGL that is there but cannot be loaded (an empty libEGL.so.1, as on many
cluster nodes) fails inside PyOpenGL with an AttributeError instead. Nothing of the room renders
through dm_control (videos use MuJoCo's own renderer, sim/envs/rendering.py a context of its
own), so then, and only with `MUJOCO_GL` unset, dm_control is imported without a renderer.
"""

from __future__ import annotations

import os
import warnings
from typing import TYPE_CHECKING, Any

import sim.mujoco_import  # noqa: F401 (mujoco first, its GL library checked)
from sim.gl_library import GL_VARIABLE
from sim.process_environment import environment_kept


def _imported() -> tuple[Any, Any]:
    with warnings.catch_warnings():
        # glfw reports its errors as warnings from its own module (glfw.GLFWError).
        warnings.filterwarnings("ignore", module="glfw")
        from dm_control import mujoco
        from dm_control.rl import control

    return mujoco, control


if TYPE_CHECKING:  # the modules' own types for the checker; at run time, as below
    from dm_control import mujoco as dm_mujoco
    from dm_control.rl import control
else:
    try:
        dm_mujoco, control = _imported()
    except (AttributeError, OSError):
        if (
            os.environ.get(GL_VARIABLE) is not None
        ):  # the user's choice: sim/mujoco_import.py names it
            raise
        with environment_kept():
            os.environ[GL_VARIABLE] = "disable"  # read once, by this import
            dm_mujoco, control = _imported()

__all__ = ["control", "dm_mujoco"]
