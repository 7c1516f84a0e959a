"""What a video draws over the rendered frames: caption, goal trajectory, events as they happen,
and the legend naming each object by its colour (experiments/video/legend.py).

World points reach the image through `CameraView`, the pinhole projection of one MuJoCo camera
at one instant (its pose from `data.cam_xpos` / `data.cam_xmat`, its vertical field of view
from `model.cam_fovy`). Pixel coordinates are (u, v) with u to the right and v down, (0, 0) at
the top-left corner of the image, as in the arrays `mujoco.Renderer.render` returns.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from PIL import Image, ImageDraw, ImageFont

from experiments.video.legend import (
    LEGEND_MIN_HEIGHT,
    draw_legend,
    geom_colour,
    legend_entries,
)
from models.layout import TRACKED_OBJECTS as TRACKED
from sim import events as ev
from sim.mujoco_import import mujoco

# Blocks of the sensory space that are object positions (5 x then 5 y, metres); the sixth
# block, "sound", is not drawn in the room.
POSITION_BLOCKS = TRACKED
# Geom whose colour stands for each tracked object in the overlay.
OBJECT_GEOMS = {
    "hand": "hand",
    "stick": "stick_handle",
    "toy1": "toy1",
    "toy2": "toy2",
    "toy3": "toy3",
}
# Body whose height is the plane the objects move in (m); every tracked object sits there.
PLANE_BODY = "stick"

# How long an event stays on screen after it happened (s of video).
EVENT_SECONDS = 1.0
# Opacity (0-255) of the goal trajectory: faint, so it does not hide the scene.
GOAL_ALPHA = 120
# Opacity of the dark boxes behind text.
BOX_ALPHA = 150
# Text height as a fraction of the frame height, and the smallest legible size (px).
FONT_FRACTION = 1 / 30
MIN_FONT_PX = 9

EVENT_LABELS = {
    ev.STICK_GRASPED: "hand grasps the stick",
    ev.TOY_GRASPED: "hand grasps {obj}",
    ev.TOY_CAUGHT: "stick catches {obj}",
    ev.TOY_MOVED: "{obj} moved by {by}",
    ev.STICK_MOVED: "stick moved by {by}",
    ev.WORD_RECOGNISED: "caregiver hears '{word}'",
    ev.CAREGIVER_SAID: "caregiver says '{word}'",
    ev.DIVERGED: "physics diverged: objects put back",
}
# Event kinds not shown: diagnostics of the voice, not things a viewer sees happen.
HIDDEN_EVENTS = {ev.FORMANT_FALLBACK}
EVENT_COLOURS = {
    ev.STICK_GRASPED: (255, 200, 60),
    ev.TOY_GRASPED: (255, 200, 60),
    ev.TOY_CAUGHT: (255, 140, 40),
    ev.WORD_RECOGNISED: (120, 220, 255),
    ev.CAREGIVER_SAID: (170, 255, 170),
    ev.DIVERGED: (255, 80, 80),
}
DEFAULT_EVENT_COLOUR = (235, 235, 235)


@dataclass(frozen=True)
class CameraView:
    """A perspective MuJoCo camera at one instant, for projecting world points to pixels.

    position: (3,) camera position in the world (m); rotation: (3, 3) camera axes as columns
    (x right, y up, z backwards: the camera looks along -z); fovy: vertical field of view
    (degrees); width, height: image size (px).
    """

    position: np.ndarray
    rotation: np.ndarray
    fovy: float
    width: int
    height: int

    @classmethod
    def of(
        cls, model: mujoco.MjModel, data: mujoco.MjData, camera: str, width: int, height: int
    ) -> CameraView:
        """The view of the named camera in the current `data` (after kinematics ran)."""
        cam = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_CAMERA, camera)
        if cam < 0:
            raise ValueError(f"the model has no camera named {camera!r}")
        if model.cam_projection[cam] != mujoco.mjtProjection.mjPROJ_PERSPECTIVE:
            raise ValueError(f"camera {camera!r} is not a perspective camera")
        return cls(
            data.cam_xpos[cam].copy(),
            data.cam_xmat[cam].reshape(3, 3).copy(),
            float(model.cam_fovy[cam]),
            width,
            height,
        )

    @property
    def focal_px(self) -> float:
        """Focal length in pixels; pixels are square, so it holds for both axes."""
        return 0.5 * self.height / np.tan(np.deg2rad(self.fovy) / 2)

    def project(self, points: np.ndarray) -> np.ndarray:
        """(n, 3) world points (m) -> (n, 2) pixel coordinates (u right, v down, float).

        Points behind the camera come back as NaN.
        """
        points = np.atleast_2d(np.asarray(points, dtype=float))
        local = (points - self.position) @ self.rotation  # camera-frame coordinates, (n, 3)
        depth = -local[:, 2]
        with np.errstate(divide="ignore", invalid="ignore"):
            u = 0.5 * self.width + self.focal_px * local[:, 0] / depth
            v = 0.5 * self.height - self.focal_px * local[:, 1] / depth
        pixels = np.column_stack([u, v])
        pixels[depth <= 0] = np.nan
        return pixels


@dataclass(frozen=True)
class Caption:
    """What the agent chose this iteration.

    model: the sensorimotor model's label (e.g. "3: arm -> toy1 | stick, toy1"), or None.
    goal: the sensory goal, or None; goal_block: the sensory block it belongs to ("hand",
    "stick", "toy1", "toy2", "toy3" or "sound"). A (10,) goal of a position block (5 x then 5 y,
    m) is drawn as a trajectory in the room.
    """

    iteration: int
    motor_space: str
    model: str | None = None
    goal: np.ndarray | None = None
    goal_block: str | None = None
    sound: str | None = None  # what the sound track is (the tract's `sound_label`)

    @property
    def goal_is_position(self) -> bool:
        return (
            self.goal is not None
            and self.goal_block in POSITION_BLOCKS
            and np.asarray(self.goal).shape == (10,)
        )


def event_label(event: ev.Event) -> str:
    """One line describing an event, e.g. 'hand grasps toy1'."""
    template = EVENT_LABELS.get(event.kind, event.kind.replace("_", " "))
    text = template.format(obj=event.obj or "?", by=event.by or "?", word=event.word or "?")
    if event.kind in (ev.WORD_RECOGNISED, ev.CAREGIVER_SAID) and event.obj:
        text += f" -> brings {event.obj}" if event.kind == ev.WORD_RECOGNISED else f" ({event.obj})"
    return text


def object_colours(model: mujoco.MjModel) -> dict[str, tuple[int, int, int]]:
    """RGB (0-255) of each tracked object, taken from its geom's material in the model."""
    return {name: geom_colour(model, geom) for name, geom in OBJECT_GEOMS.items()}


def object_plane_height(model: mujoco.MjModel) -> float:
    """Height (m) of the plane the tracked objects move in."""
    body = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, PLANE_BODY)
    return float(model.body_pos[body, 2])


def describe_goal(caption: Caption) -> str:
    if caption.goal is None:
        return "goal: none"
    block = caption.goal_block or "?"
    if caption.goal_is_position:
        return f"goal: {block} trajectory (drawn)"
    return f"goal: {block} ({np.asarray(caption.goal).size}D)"


class Overlay:
    """Draws the caption, the goal and the recent events into frames of one size.

    model: the MuJoCo model (object colours, the objects' plane); fps: frames per second of
    the video, which decides how many frames an event stays (`event_seconds`).
    """

    def __init__(
        self,
        model: mujoco.MjModel,
        width: int,
        height: int,
        fps: float,
        event_seconds: float = EVENT_SECONDS,
    ) -> None:
        self.width, self.height = width, height
        self.colours = object_colours(model)
        self.legend = legend_entries(model)
        self.plane_z = object_plane_height(model)
        self.event_frames = max(1, int(round(event_seconds * fps)))
        size = max(MIN_FONT_PX, int(round(height * FONT_FRACTION)))
        self.font = ImageFont.load_default(size=size)
        self.line_px = size + max(2, size // 4)
        self.margin = max(2, size // 2)

    def draw(
        self,
        frame: np.ndarray,
        view: CameraView,
        caption: Caption,
        tick: int,
        n_steps: int,
        events: Sequence[ev.Event] = (),
        positions: np.ndarray | None = None,
    ) -> np.ndarray:
        """The frame (h, w, 3) uint8 with the overlay drawn in; a new array.

        tick: the frame's control step (1..n_steps during the movement, <= 0 before it, >
        n_steps in the frames held after it); an event of step k shows while k <= tick <
        k + event_frames. positions: (n_steps, 5, 2) tracked objects after each step (m), to
        ring the object an event is about.
        """
        base = Image.fromarray(frame).convert("RGBA")
        layer = Image.new("RGBA", base.size, (0, 0, 0, 0))
        pen = ImageDraw.Draw(layer)
        if caption.goal_is_position:
            self._draw_goal(pen, view, caption)
        shown = [
            e
            for e in events
            if e.kind not in HIDDEN_EVENTS and e.step <= tick < e.step + self.event_frames
        ]
        if positions is not None:
            self._ring_objects(pen, view, shown, positions, tick, n_steps)
        step_text = (
            "before" if tick <= 0 else f"step {tick}/{n_steps}" if tick <= n_steps else "after"
        )
        lines = [
            f"iteration {caption.iteration}  {caption.motor_space}  {step_text}",
            f"model: {caption.model or 'none'}",
            describe_goal(caption),
            *([caption.sound] if caption.sound else []),
        ]
        self._text_box(pen, lines, [DEFAULT_EVENT_COLOUR] * len(lines), top=True)
        if self.height >= LEGEND_MIN_HEIGHT:
            draw_legend(pen, self.legend, self.font, self.line_px, self.margin, self.width)
        if shown:
            labels = [f"{e.step:2d}  {event_label(e)}" for e in shown]
            colours = [EVENT_COLOURS.get(e.kind, DEFAULT_EVENT_COLOUR) for e in shown]
            self._text_box(pen, labels, colours, top=False)
        return np.asarray(Image.alpha_composite(base, layer).convert("RGB"))

    # Parts --------------------------------------------------------------------------------
    def _draw_goal(self, pen: ImageDraw.ImageDraw, view: CameraView, caption: Caption) -> None:
        goal = np.asarray(caption.goal, dtype=float)
        points = np.column_stack([goal[:5], goal[5:], np.full(5, self.plane_z)])
        pixels = view.project(points)
        pixels = pixels[np.isfinite(pixels).all(axis=1)]
        if len(pixels) == 0:
            return
        assert caption.goal_block is not None  # drawn only when goal_is_position
        colour = (*self.colours.get(caption.goal_block, DEFAULT_EVENT_COLOUR), GOAL_ALPHA)
        width = max(1, self.height // 160)
        pen.line([tuple(p) for p in pixels], fill=colour, width=width, joint="curve")
        radius = max(2, self.height // 120)
        for k, (u, v) in enumerate(pixels):
            # The last sample, where the goal ends, is drawn larger.
            r = 2 * radius if k == len(pixels) - 1 else radius
            pen.ellipse((u - r, v - r, u + r, v + r), fill=colour)

    def _ring_objects(
        self,
        pen: ImageDraw.ImageDraw,
        view: CameraView,
        shown: Sequence[ev.Event],
        positions: np.ndarray,
        tick: int,
        n_steps: int,
    ) -> None:
        row = min(max(tick, 1), n_steps) - 1
        radius = max(4, self.height // 30)
        for event in shown:
            if event.obj not in TRACKED:
                continue
            xy = positions[row, TRACKED.index(event.obj)]
            (u, v) = view.project(np.array([[*xy, self.plane_z]]))[0]
            if not np.isfinite([u, v]).all():
                continue
            colour = (*EVENT_COLOURS.get(event.kind, DEFAULT_EVENT_COLOUR), 230)
            pen.ellipse(
                (u - radius, v - radius, u + radius, v + radius),
                outline=colour,
                width=max(1, self.height // 200),
            )

    def _text_box(
        self,
        pen: ImageDraw.ImageDraw,
        lines: Sequence[str],
        colours: Sequence[tuple[int, int, int]],
        top: bool,
    ) -> None:
        m = self.margin
        widths = [pen.textlength(line, font=self.font) for line in lines]
        box_w = min(self.width - 2 * m, max(widths) + 2 * m)
        box_h = len(lines) * self.line_px + m
        y0 = m if top else self.height - m - box_h
        pen.rectangle((m, y0, m + box_w, y0 + box_h), fill=(0, 0, 0, BOX_ALPHA))
        for k, (line, colour) in enumerate(zip(lines, colours, strict=True)):
            pen.text((2 * m, y0 + m // 2 + k * self.line_px), line, font=self.font, fill=colour)
