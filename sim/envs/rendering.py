"""Frames of the room for the Gymnasium environment's render modes: "rgb_array" with MuJoCo's
offscreen renderer, "human" in MuJoCo's passive viewer; what a frame after a step shows, the
room at the movement's end (`MovementEnd`).

The offscreen backend is chosen as for videos (experiments/video/gl.py, which sim cannot
import): the one `MUJOCO_GL` names, EGL when it is unset. MuJoCo picks its own GL context class
once, when first imported (GLFW with `MUJOCO_GL` unset, which needs a display), so the
renderer makes its context from the chosen backend's module itself: an environment whose
room was built before anything rendered still renders offscreen. A backend's module is
imported on the first render: an environment that never renders loads no GL library of its
own (MuJoCo loads what `MUJOCO_GL` names at its import, nothing under `disable`).
"""

from __future__ import annotations

import atexit
import importlib
import os
import threading
import weakref
from typing import Any

import numpy as np

from sim.gl_library import GL_VARIABLE, gl_library_problem
from sim.mujoco_import import mujoco
from sim.process_environment import environment_kept

BACKENDS = ("egl", "osmesa", "glfw")
DEFAULT_BACKEND = "egl"
DEFAULT_SIZE = (640, 480)  # width, height (px), as videos
CAMERAS = ("top", "hand_view")  # models/playroom.xml
# How long closing the viewer waits for its window's thread (GLFW would pull the window from
# under a running thread at exit: a segmentation fault).
VIEWER_CLOSE_WAIT_S = 10.0


class RenderError(RuntimeError):
    """The room cannot be rendered here; the message says why and what to set, in one line."""


def backend() -> str:
    """The offscreen backend: MUJOCO_GL's value, else EGL; RenderError for one that cannot
    render offscreen (MUJOCO_GL=disable included)."""
    chosen = os.environ.get(GL_VARIABLE, "").strip().lower() or DEFAULT_BACKEND
    if chosen not in BACKENDS:
        raise RenderError(
            f"{GL_VARIABLE}={chosen!r} cannot render: set it to one of {', '.join(BACKENDS)}, "
            f"or unset it ({DEFAULT_BACKEND})"
        )
    return chosen


def context_class() -> Any:
    """The GL context class of the chosen backend (mujoco.egl.GLContext, ...), its module
    imported if MuJoCo chose another; RenderError in one line if it cannot be loaded."""
    chosen = backend()
    problem = gl_library_problem(chosen)
    if problem is not None:
        raise RenderError(problem)
    loaded = getattr(mujoco, "GLContext", None)
    if loaded is not None and loaded.__module__.split(".")[1] == chosen:
        return loaded
    try:
        # mujoco.egl and mujoco.osmesa set PYOPENGL_PLATFORM for PyOpenGL, which reads it once,
        # at this import: put back, as sim sets no environment variable.
        with environment_kept():
            module = importlib.import_module(f"mujoco.{chosen}")
    except Exception as exc:  # PyOpenGL raises ImportError, AttributeError, OSError, ...
        raise RenderError(
            f"the OpenGL backend {GL_VARIABLE}={chosen} cannot be loaded "
            f"({type(exc).__name__}: {exc}); set {GL_VARIABLE} to one of {', '.join(BACKENDS)}"
        ) from None
    return module.GLContext


def checked_view(model: Any, size: tuple[int, int], camera: str) -> tuple[int, int]:
    """(width, height) of a frame, checked against the model's cameras and offscreen buffer;
    ValueError in one line."""
    if mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_CAMERA, camera) < 0:
        raise ValueError(f"unknown camera {camera!r}: choose one of {list(CAMERAS)}")
    try:
        width, height = (int(side) for side in size)
    except (TypeError, ValueError):
        raise ValueError(f"render_size must be (width, height) in px, got {size!r}") from None
    limit = (model.vis.global_.offwidth, model.vis.global_.offheight)
    if not (0 < width <= limit[0] and 0 < height <= limit[1]):
        raise ValueError(
            f"render_size {width}x{height} is outside the model's offscreen buffer "
            f"{limit[0]}x{limit[1]} (<visual><global offwidth offheight> in the MJCF)"
        )
    return width, height


class OffscreenRenderer:
    """RGB frames (height, width, 3) uint8 of a model's state from one of its cameras, in a GL
    context of its own (what mujoco.Renderer does, with the context chosen here). One not closed
    is closed when collected or at exit, before MuJoCo's EGL display is terminated: an EGL
    context freed after that (by the garbage collector at exit) prints an EGLError traceback."""

    def __init__(
        self, model: Any, size: tuple[int, int] = DEFAULT_SIZE, camera: str = "top"
    ) -> None:
        self.width, self.height = checked_view(model, size, camera)
        self.model = model
        context = context_class()
        try:
            self._context = context(self.width, self.height)
            self._context.make_current()
            self._mjr = mujoco.MjrContext(model, mujoco.mjtFontScale.mjFONTSCALE_150)
        except Exception as exc:  # a driver that loads but cannot make a context
            raise RenderError(
                f"cannot create an offscreen GL context with {GL_VARIABLE}={backend()} "
                f"({type(exc).__name__}: {exc}); set {GL_VARIABLE} to one of {', '.join(BACKENDS)}"
            ) from None
        mujoco.mjr_setBuffer(mujoco.mjtFramebuffer.mjFB_OFFSCREEN, self._mjr)
        # The GL objects are freed by a finalizer that holds them, not the renderer, so that it
        # runs when the renderer is collected. At exit it must run before mujoco.egl's atexit
        # hook terminates the display: atexit runs hooks last registered first, and this one is
        # registered after the context (hence after that hook), whereas weakref.finalize's own
        # exit hook may have been registered before it, by any library's first finalizer.
        self._free = weakref.finalize(self, _free_gl, self._context, self._mjr)
        self._free.atexit = False
        atexit.register(self._free)
        self._scene = mujoco.MjvScene(model, maxgeom=1000)
        self._option = mujoco.MjvOption()
        self._camera = mujoco.MjvCamera()
        self._camera.type = mujoco.mjtCamera.mjCAMERA_FIXED
        self._camera.fixedcamid = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_CAMERA, camera)
        self._rect = mujoco.MjrRect(0, 0, self.width, self.height)

    def render(self, data: Any) -> np.ndarray:
        """The frame of `data` (an MjData of the model) as it is now."""
        if self._mjr is None:
            raise RuntimeError("the renderer is closed")
        self._context.make_current()
        mujoco.mjv_updateScene(
            self.model, data, self._option, None, self._camera, mujoco.mjtCatBit.mjCAT_ALL,
            self._scene,
        )  # fmt: skip
        # No shadows, as in videos: on Mesa's software EGL they halve the frame rate, and from
        # the top camera they wash out the table.
        self._scene.flags[mujoco.mjtRndFlag.mjRND_SHADOW] = False
        mujoco.mjr_render(self._rect, self._scene, self._mjr)
        frame = np.empty((self.height, self.width, 3), dtype=np.uint8)
        mujoco.mjr_readPixels(frame, None, self._rect, self._mjr)
        return np.flipud(frame).copy()  # OpenGL's rows run bottom-up

    def close(self) -> None:
        """Frees the GL context now (a second close does nothing)."""
        if self._mjr is not None:
            self._free()
            atexit.unregister(self._free)
            self._mjr = None


def _free_gl(context: Any, mjr: Any) -> None:
    """Frees a renderer's MuJoCo GL objects, then its context."""
    context.make_current()
    mjr.free()
    context.free()


class MovementEnd:
    """The room's pose (joint positions and mocap bodies) at the last control step of its last
    movement, from the movement's trace (sim/movement.py): after it the room puts the arm back
    to rest, drops what is held and places things for the next command, so the room as it is
    after a step no longer shows the movement. From now on the room traces its movements
    (`Playroom.tracing`: the same world, a few copies of its joints a step more)."""

    def __init__(self, room: Any) -> None:
        self.room = room
        room.tracing = True
        self._forgotten = room.last_trace

    def forget(self) -> None:
        """No pose kept: until the next movement ends, frames show the room as it is."""
        self._forgotten = self.room.last_trace

    @property
    def pose(self) -> tuple[np.ndarray, np.ndarray, np.ndarray] | None:
        """(qpos, mocap_pos, mocap_quat) at the last movement's end, or None."""
        path = self.path
        return None if path is None else path[-1]

    @property
    def path(self) -> list[tuple[np.ndarray, np.ndarray, np.ndarray]] | None:
        """(qpos, mocap_pos, mocap_quat) after each control step of the last movement, first to
        last (the trace's rows 1 to N_STEPS; row 0 is the room before it), or None."""
        trace = self.room.last_trace
        if trace is None or trace is self._forgotten:
            return None
        quat = self.room.physics.data.ptr.mocap_quat
        return [(trace.qpos[k], trace.mocap_pos[k], quat) for k in range(1, len(trace.qpos))]


def display_missing() -> str | None:
    """Why the viewer cannot open a window here, in one line; None where a display exists."""
    if os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY"):
        return None
    return (
        "render_mode 'human' opens MuJoCo's viewer, which needs a display (neither DISPLAY nor "
        "WAYLAND_DISPLAY is set); use render_mode='rgb_array' on a machine without one"
    )


class Viewer:
    """MuJoCo's passive viewer of one model and its data, shown as it is at each `show`."""

    def __init__(self, model: Any, data: Any) -> None:
        missing = display_missing()
        if missing is not None:
            raise RenderError(missing)
        import mujoco.viewer

        before = set(threading.enumerate())
        self._handle = mujoco.viewer.launch_passive(
            model, data, show_left_ui=False, show_right_ui=False
        )
        self._threads = set(threading.enumerate()) - before

    def show(self) -> None:
        self._handle.sync()

    def is_running(self) -> bool:
        return bool(self._handle.is_running())

    def close(self) -> None:
        self._handle.close()
        for thread in self._threads:
            thread.join(VIEWER_CLOSE_WAIT_S)
