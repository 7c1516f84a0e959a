"""Offscreen frames of a room: one per control step, each with the camera view it was taken from.

A `FrameRecorder` renders a room's scene with MuJoCo's offscreen renderer, on demand or, for a
movement it films, at every control step, drawn from the movement's trace (sim/movement.py)
after the movement: the movement itself is computed as in a trial. Rendering uses the OpenGL
backend MuJoCo loaded (`MUJOCO_GL`): this module never sets it, because mujoco reads it once at
its first import and the `playroom` command chooses it before that (experiments/video/gl.py).
"""

from __future__ import annotations

import os
import re
from collections.abc import Sequence

import numpy as np

from experiments.video import gl
from experiments.video.encoding import RenderError
from experiments.video.overlay import CameraView
from models.world import Feedback
from sim import Playroom
from sim.mujoco_import import mujoco
from sim.physics import PlayroomPhysics

DEFAULT_SIZE = (640, 480)  # width, height (px)
CAMERAS = ("top", "hand_view")


def parse_size(size: str | Sequence[int]) -> tuple[int, int]:
    """'WxH' or (width, height) -> (width, height) in px; ValueError unless both are positive
    even integers (H.264 in 4:2:0 needs even sides)."""
    if isinstance(size, str):
        match = re.fullmatch(r"\s*(\d+)\s*[xX]\s*(\d+)\s*", size)
        if match is None:
            raise ValueError(f"size must be WxH with positive integers, e.g. 640x480, got {size!r}")
        width, height = int(match[1]), int(match[2])
    else:
        try:
            width, height = size
        except (TypeError, ValueError):
            raise ValueError(f"size must be (width, height), got {size!r}") from None
        if not all(isinstance(v, int | np.integer) and not isinstance(v, bool) for v in size):
            raise ValueError(f"size must be two integers (width, height), got {size!r}")
        width, height = int(width), int(height)
    if width <= 0 or height <= 0:
        raise ValueError(f"size must be positive, got {width}x{height}")
    if width % 2 or height % 2:
        raise ValueError(f"size must have even width and height for H.264, got {width}x{height}")
    return width, height


def _check_camera_in_model(camera: str, model: mujoco.MjModel) -> None:
    # A recorder may be given any camera of the MJCF, so the model, not `CAMERAS`, decides.
    if mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_CAMERA, camera) < 0:
        raise ValueError(f"unknown camera {camera!r}: choose one of {list(CAMERAS)}")


class FrameRecorder:
    """Renders a room's scene offscreen: on demand (`capture`) and at every control step of a
    movement (`film`).

    size: (width, height) px; camera: a camera of the MJCF ("top" or "hand_view"); shadows:
    MuJoCo's shadow maps, off by default: on Mesa's software EGL they halve the frame rate, and
    from the top camera they wash out the table and hide the reach circles. Frames are
    (height, width, 3) uint8; each comes with the `CameraView` it was taken from. Close it
    (or use it as a context manager): an EGL context left to the garbage collector at exit
    prints errors.
    """

    def __init__(
        self,
        room: Playroom,
        size: tuple[int, int] = DEFAULT_SIZE,
        camera: str = "top",
        shadows: bool = False,
    ) -> None:
        self.width, self.height = parse_size(size)
        self.room = room
        self.camera = camera
        self.shadows = bool(shadows)
        model = room.physics.model.ptr
        _check_camera_in_model(camera, model)
        limit = (model.vis.global_.offwidth, model.vis.global_.offheight)
        if self.width > limit[0] or self.height > limit[1]:
            raise ValueError(
                f"size {self.width}x{self.height} exceeds the model's offscreen buffer "
                f"{limit[0]}x{limit[1]} (<visual><global offwidth offheight> in the MJCF)"
            )
        try:
            self._renderer = mujoco.Renderer(model, self.height, self.width)
        except Exception as exc:  # the GL backends raise many kinds; all mean the same here
            raise RenderError(
                f"cannot create an offscreen renderer with "
                f"{gl.VARIABLE}={os.environ.get(gl.VARIABLE, '(unset)')} "
                f"({type(exc).__name__}: {exc}); {gl.choices()}"
            ) from exc
        self.frames: list[np.ndarray] = []
        self.views: list[CameraView] = []

    def capture(self, physics: PlayroomPhysics | None = None) -> np.ndarray:
        """Render the room as it is now (or `physics`, a posed copy of it); append and return
        the frame."""
        physics = self.room.physics if physics is None else physics
        model, data = physics.model.ptr, physics.data.ptr
        self._renderer.update_scene(data, camera=self.camera)
        self._renderer.scene.flags[mujoco.mjtRndFlag.mjRND_SHADOW] = self.shadows
        frame = self._renderer.render()
        self.frames.append(frame)
        self.views.append(CameraView.of(model, data, self.camera, self.width, self.height))
        return frame

    def film(self, motor_space: str, m: np.ndarray) -> Feedback:
        """`room.act(motor_space, m)`, then one frame per control step of the movement, drawn
        from its trace; returns the feedback. A refused or failed command adds no frame."""
        room = self.room
        tracing = room.tracing
        room.tracing = True
        try:
            feedback = room.act(motor_space, m)
        finally:
            room.tracing = tracing
        assert room.last_trace is not None  # traced: act ran
        for _, posed in room.last_trace.replayed(room.physics):
            self.capture(posed)
        return feedback

    def take(self) -> tuple[list[np.ndarray], list[CameraView]]:
        """The frames and views captured so far; the recorder starts empty again."""
        frames, views = self.frames, self.views
        self.frames, self.views = [], []
        return frames, views

    def close(self) -> None:
        """Release the GL context (idempotent)."""
        if self._renderer is not None:
            self._renderer.close()
            self._renderer = None

    def __enter__(self) -> FrameRecorder:
        return self

    def __exit__(self, *exc_info: object) -> None:
        self.close()


# Speed (the `render` section of `playroom bench`) ---------------------------------------------
