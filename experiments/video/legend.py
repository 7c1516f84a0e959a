"""The legend in a corner of every video frame: a coloured dot and a name for each toy, the
stick and the caregiver, so that a viewer knows which dot is which without the model file.

Colours are read from the model's materials (models/playroom.xml), never restated here; the
colour word beside each name is the nearest of a few plain colour names.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from PIL import ImageDraw, ImageFont

from sim.mujoco_import import mujoco

# What the legend names (as the event captions name it), and the geom whose material gives its
# colour. The stick is named by its handle, the part the hand grasps and the brightest.
LEGEND_GEOMS = (
    ("toy1", "toy1"),
    ("toy2", "toy2"),
    ("toy3", "toy3"),
    ("stick", "stick_handle"),
    ("caregiver", "caregiver"),
)
# Plain colour names (RGB 0-255) a viewer would use; each legend colour takes the nearest.
COLOUR_WORDS = {
    "red": (215, 40, 40),
    "green": (40, 180, 50),
    "blue": (50, 90, 220),
    "purple": (150, 50, 200),
    "orange": (245, 140, 25),
    "yellow": (230, 195, 75),
    "brown": (140, 90, 50),
    "grey": (128, 128, 128),
}
# Frames shorter than this (px) get no legend: its five lines would cover a third of the room
# (at 160x120 they hide the arm); the default 640x480 has room for it.
LEGEND_MIN_HEIGHT = 240
# Opacity (0-255) of the box behind the legend, as behind the other text.
LEGEND_BOX_ALPHA = 150


def geom_colour(model: mujoco.MjModel, geom_name: str) -> tuple[int, int, int]:
    """RGB (0-255) of a geom: its material's colour, or its own where it has no material."""
    geom = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_GEOM, geom_name)
    if geom < 0:
        raise ValueError(f"the model has no geom {geom_name!r} for the video's legend")
    mat = model.geom_matid[geom]
    rgba = model.mat_rgba[mat] if mat >= 0 else model.geom_rgba[geom]
    r, g, b = (int(round(255 * c)) for c in rgba[:3])
    return (r, g, b)


def colour_word(rgb: Sequence[int]) -> str:
    """The nearest plain colour name of an RGB colour (0-255)."""
    names = list(COLOUR_WORDS)
    palette = np.array([COLOUR_WORDS[n] for n in names], dtype=float)
    return names[int(np.argmin(np.linalg.norm(palette - np.asarray(rgb, float), axis=1)))]


def legend_entries(model: mujoco.MjModel) -> list[tuple[str, tuple[int, int, int]]]:
    """("toy1 (red)", its RGB), ... for every entry of LEGEND_GEOMS, in that order."""
    entries = []
    for name, geom in LEGEND_GEOMS:
        rgb = geom_colour(model, geom)
        entries.append((f"{name} ({colour_word(rgb)})", rgb))
    return entries


def draw_legend(
    pen: ImageDraw.ImageDraw,
    entries: Sequence[tuple[str, tuple[int, int, int]]],
    font: ImageFont.ImageFont | ImageFont.FreeTypeFont,
    line_px: int,
    margin: int,
    width: int,
) -> None:
    """The entries in a dark box at the top-right corner of an image `width` px wide: a dot
    of each colour, its name beside it in light grey."""
    m = margin
    dot = max(3, line_px // 3)
    text_w = max(pen.textlength(label, font=font) for label, _ in entries)
    box_w = int(text_w + 2 * dot + 3 * m)
    box_h = len(entries) * line_px + m
    x0 = width - m - box_w
    pen.rectangle((x0, m, x0 + box_w, m + box_h), fill=(0, 0, 0, LEGEND_BOX_ALPHA))
    for k, (label, rgb) in enumerate(entries):
        y = m + m // 2 + k * line_px
        cx, cy = x0 + m + dot, y + line_px // 2 - 1
        pen.ellipse((cx - dot, cy - dot, cx + dot, cy + dot), fill=(*rgb, 255))
        pen.text((cx + dot + m, y), label, font=font, fill=(235, 235, 235))
