"""The video's legend (experiments/video/legend.py): each toy, the stick and the caregiver
named by the colour the model gives them, drawn as coloured dots in a corner box."""

from __future__ import annotations

from pathlib import Path

import mujoco
import numpy as np
import pytest

from experiments.video.legend import colour_word, legend_entries
from experiments.video.overlay import CameraView, Caption, Overlay

MODEL = Path(__file__).resolve().parents[2] / "models" / "playroom.xml"


@pytest.fixture(scope="module")
def model() -> mujoco.MjModel:
    return mujoco.MjModel.from_xml_path(str(MODEL))


def test_each_object_is_named_by_the_colour_of_its_material(model):
    names = [label for label, _ in legend_entries(model)]
    assert names == [
        "toy1 (red)",
        "toy2 (green)",
        "toy3 (purple)",
        "stick (orange)",
        "caregiver (yellow)",
    ]
    assert colour_word((20, 60, 230)) == "blue"


def test_the_legend_is_drawn_as_coloured_dots_in_the_top_right_corner(model):
    width, height = 480, 360
    overlay = Overlay(model, width, height, fps=25)
    view = CameraView(np.array([0.0, 0.0, 2.0]), np.eye(3), 45.0, width, height)
    frame = np.zeros((height, width, 3), np.uint8)
    drawn = overlay.draw(frame, view, Caption(iteration=1, motor_space="arm"), 1, 50)
    corner = drawn[: height // 2, width // 2 :].reshape(-1, 3).astype(int)
    left = drawn[height // 2 :, : width // 4].reshape(-1, 3).astype(int)
    for _, rgb in legend_entries(model):
        # Each object's colour (a dot) is in the corner and nowhere in the empty bottom-left.
        assert (np.abs(corner - rgb).max(axis=1) <= 2).sum() >= 9, rgb
        assert not (np.abs(left - rgb).max(axis=1) <= 2).any(), rgb


def test_frames_too_small_for_a_legend_get_none(model):
    width, height = 160, 120  # the legend would hide a third of the room
    overlay = Overlay(model, width, height, fps=25)
    view = CameraView(np.array([0.0, 0.0, 2.0]), np.eye(3), 45.0, width, height)
    frame = np.zeros((height, width, 3), np.uint8)
    drawn = overlay.draw(frame, view, Caption(iteration=1, motor_space="arm"), 1, 50)
    pixels = drawn.reshape(-1, 3).astype(int)
    for _, rgb in legend_entries(model):
        assert not (np.abs(pixels - rgb).max(axis=1) <= 2).any(), rgb
