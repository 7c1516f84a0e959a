"""`playroom view` opens MuJoCo's viewer on a display (here a virtual one, Xvfb) and shows the
room in it; without a display it says so in one line."""

from __future__ import annotations

import contextlib
import os
import shutil
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

PLAYROOM = [sys.executable, "-m", "experiments.cli.main"]
DISPLAY = ":87"  # a number no desktop takes


def test_without_a_display_view_is_one_line(tmp_path):
    env = {k: v for k, v in os.environ.items() if k not in ("DISPLAY", "WAYLAND_DISPLAY")}
    result = subprocess.run(
        [*PLAYROOM, "view", "--random"], env=env, capture_output=True, text=True, cwd=tmp_path
    )
    assert result.returncode == 2
    assert result.stderr.strip().splitlines() == [
        "playroom view: error: a display is needed (neither DISPLAY nor WAYLAND_DISPLAY is set); "
        "on a machine without one, film the trial instead: playroom render"
    ]


@pytest.fixture
def xvfb():
    """A virtual X display, for as long as the test runs."""
    if shutil.which("Xvfb") is None or shutil.which("import") is None:
        pytest.skip(
            "Xvfb or ImageMagick's `import` is not installed (apt-get install xvfb imagemagick)"
        )
    server = subprocess.Popen(
        ["Xvfb", DISPLAY, "-screen", "0", "800x600x24", "-nolisten", "tcp"],
        stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
    )  # fmt: skip
    socket = Path(f"/tmp/.X11-unix/X{DISPLAY[1:]}")
    for _ in range(100):  # until it listens (at most 10 s)
        if socket.exists():
            break
        time.sleep(0.1)
    yield DISPLAY
    server.terminate()
    server.wait()


def _screenshot(display: str, path: Path) -> np.ndarray | None:
    from PIL import Image

    done = subprocess.run(
        ["import", "-display", display, "-window", "root", str(path)], capture_output=True
    )
    return np.asarray(Image.open(path).convert("RGB")) if done.returncode == 0 else None


# About 30 s on the loaded 2-core machine (a fresh interpreter, the window, 8 s of iterations):
# `make test-slow` runs it.
@pytest.mark.slow
def test_view_opens_the_viewer_and_shows_the_room(xvfb, tmp_path):
    env = {k: v for k, v in os.environ.items() if k not in ("MUJOCO_GL", "WAYLAND_DISPLAY")}
    env["DISPLAY"] = xvfb
    viewer = subprocess.Popen(
        [*PLAYROOM, "view", "--random", "--iterations", "4", "--pace", "0.5"],
        env=env, cwd=tmp_path, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
    )  # fmt: skip
    shown = None
    try:
        while viewer.poll() is None and shown is None:
            image = _screenshot(xvfb, tmp_path / "screen.png")
            # An empty X screen is one colour; the viewer's scene is many.
            if image is not None and len(np.unique(image.reshape(-1, 3), axis=0)) > 50:
                shown = image
            time.sleep(0.3)
        out, err = viewer.communicate(timeout=120)
    finally:
        viewer.kill()
    assert viewer.returncode == 0, err
    assert out.strip() == "4 iterations shown"
    assert shown is not None, "the viewer's window never showed the room"


def test_a_trial_is_viewed_only_within_its_iterations(tmp_path):
    from experiments.run.settings import TrialSettings
    from experiments.run.trial import run_trial
    from experiments.video.viewer import ViewError, view_trial

    run_trial(tmp_path / "t", TrialSettings(iterations=3, checkpoint_every=3), progress=False)
    with pytest.raises(ViewError, match=r"--from 3 is out of range: the trial has 0\.\.2"):
        view_trial(tmp_path / "t", start=3, count=1)
    with pytest.raises(ViewError, match="holds no trial"):
        view_trial(tmp_path, start=0, count=1)


class _FakeViewer:
    """What `_Window` uses of MuJoCo's passive viewer, keeping the hand shown at each sync."""

    def __init__(self, shown) -> None:
        self.shown, self.hands = shown, []

    def is_running(self) -> bool:
        return True

    def lock(self):
        return contextlib.nullcontext()

    def sync(self) -> None:
        self.hands.append(self.shown.hand_position())


@pytest.mark.parametrize("grasp", ["kinematic", "physical"])
def test_the_window_shows_every_step_of_a_movement_then_the_room(grasp):
    from experiments.video.viewer import _Window
    from sim import Playroom

    room = Playroom(grasp, seed=0)
    shown = room.physics.copy(share_model=True)
    fake = _FakeViewer(shown)
    window = _Window(room, fake, shown, pace=1000.0)
    feedback = window.act("arm", np.random.default_rng(0).uniform(-1, 1, 21))
    hands = np.array(fake.hands)
    assert len(hands) == 1 + 50 + 1  # the room, each control step, the room again
    np.testing.assert_allclose(hands[1:51], feedback.positions[:, 0], atol=1e-12)
    np.testing.assert_array_equal(hands[-1], room.physics.hand_position())
    np.testing.assert_array_equal(shown.data.ptr.qpos, room.physics.data.ptr.qpos)
