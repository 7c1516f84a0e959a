"""The Gymnasium environment's render modes (sim/envs/rendering.py): "rgb_array" frames of the
room, offscreen, that follow it and change nothing of it; "human" in MuJoCo's viewer where a
display exists, one line where none does; no GL at all without a render mode."""

from __future__ import annotations

import os
import subprocess
import sys

import gymnasium
import mujoco
import numpy as np
import pytest
from gymnasium.utils.passive_env_checker import env_render_passive_checker

from experiments.video.overlay import CameraView
from sim.envs import GYM_ID, PlayroomGymEnv
from sim.envs.rendering import RenderError

SIZE = (320, 240)
# Asymmetric places, so that a flipped axis would miss.
TOYS = np.array([[0.45, -0.3], [-0.6, 0.25], [0.15, 0.7]])


def test_rgb_array_frames_show_the_room_where_it_is():
    env = gymnasium.make(GYM_ID, render_mode="rgb_array", render_size=SIZE)
    env.reset(seed=0)
    room = env.unwrapped.movement_env.room
    room.arrange(toys=TOYS)
    frame = env.render()
    env_render_passive_checker(env.unwrapped)  # Gymnasium's own checks of a render
    env.close()
    assert frame.shape == (SIZE[1], SIZE[0], 3) and frame.dtype == np.uint8
    model, data = room.physics.model.ptr, room.physics.data.ptr
    view = CameraView.of(model, data, "top", *SIZE)
    dominant = {"toy1": 0, "toy2": 1, "toy3": 2}  # red, green, purple (blue is largest)
    for name, channel in dominant.items():
        body = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, name)
        u, v = view.project(data.xpos[body])[0]
        rgb = frame[int(v), int(u)].astype(int)
        assert rgb.argmax() == channel and rgb.max() - rgb.min() > 40, (name, rgb)
        # Ten pixels away is the table, not the toy: the check can tell them apart.
        away = frame[int(v), int(u) + 10].astype(int)
        assert away.max() - away.min() < 40, (name, away)


def _episode(render_mode: str | None) -> tuple[list[np.ndarray], list[np.ndarray]]:
    env = PlayroomGymEnv(grasp="physical", iterations=10, render_mode=render_mode)
    env.action_space.seed(3)
    observations, frames = [env.reset(seed=2)[0]], []
    if render_mode is not None:  # from here on the episode's movements are watched
        frames.append(env.render())
    for _ in range(4):
        observations.append(env.step(env.action_space.sample())[0])
        if render_mode is not None:
            frames.append(env.render())
    env.close()
    return observations, frames


def test_rendering_follows_the_room_and_changes_nothing_of_it():
    plain, _ = _episode(None)
    # Watched movements are stepped one control step at a time: the same world, bit for bit.
    rendered, frames = _episode("rgb_array")
    np.testing.assert_array_equal(np.array(rendered), np.array(plain))
    # Each movement moves the arm (or says something and the arm rests): frames differ.
    assert any(not np.array_equal(a, b) for a, b in zip(frames, frames[1:], strict=False))


def test_a_new_episode_renders_its_own_room():
    env = PlayroomGymEnv(iterations=10, render_mode="rgb_array", render_size=SIZE)
    env.reset(seed=0)
    first = env.render()
    env.reset(seed=1)  # another seed: the toys elsewhere
    second = env.render()
    env.reset(seed=0)
    again = env.render()
    env.close()
    assert not np.array_equal(first, second)
    np.testing.assert_array_equal(first, again)


def test_render_without_a_render_mode_warns_and_returns_none():
    env = PlayroomGymEnv(iterations=10)
    env.reset(seed=0)
    with pytest.warns(UserWarning, match='render_mode="rgb_array"'):
        assert env.render() is None


def test_the_viewer_without_a_display_is_one_line(monkeypatch):
    monkeypatch.delenv("DISPLAY", raising=False)
    monkeypatch.delenv("WAYLAND_DISPLAY", raising=False)
    with pytest.raises(RenderError) as caught:
        PlayroomGymEnv(render_mode="human")
    assert str(caught.value) == (
        "render_mode 'human' opens MuJoCo's viewer, which needs a display (neither DISPLAY nor "
        "WAYLAND_DISPLAY is set); use render_mode='rgb_array' on a machine without one"
    )


GL_MODULES = ("OpenGL", "glfw", "mujoco.egl", "mujoco.osmesa", "mujoco.glfw")


def test_without_a_render_mode_no_gl_is_loaded_and_a_disabled_gl_cannot_render():
    code = f"""
import sys, gymnasium
env = gymnasium.make("sim.envs:{GYM_ID}")
env.reset(seed=0)
env.step(env.action_space.sample())
print(sorted(m for m in {GL_MODULES!r} if m in sys.modules))
env = gymnasium.make("sim.envs:{GYM_ID}", render_mode="rgb_array")
env.reset(seed=0)
env.render()
"""
    # MUJOCO_GL=disable: MuJoCo itself then loads none (unset, it loads GLFW at its import).
    env = dict(os.environ, MUJOCO_GL="disable")
    result = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True)
    assert result.stdout.strip() == "[]"
    assert result.stderr.strip().splitlines()[-1] == (
        "sim.envs.rendering.RenderError: MUJOCO_GL='disable' cannot render: set it to one of "
        "egl, osmesa, glfw, or unset it (egl)"
    )


HUMAN = f"""
import sys, time, warnings
import gymnasium
from gymnasium.utils.env_checker import check_env
env = gymnasium.make("sim.envs:{GYM_ID}")
with warnings.catch_warnings():
    warnings.simplefilter("error")
    check_env(env.unwrapped)  # every declared render mode, "human" included
env = gymnasium.make("sim.envs:{GYM_ID}", render_mode="human")
env.reset(seed=0)
for _ in range(6):
    env.step(env.action_space.sample())
    print("stepped", flush=True)
    time.sleep(0.5)
env.close()
"""


# About 15 s (a fresh interpreter, the checker's rooms, the window): `make test-slow` runs it.
@pytest.mark.slow
def test_the_viewer_shows_the_room_on_a_display(tmp_path):
    import shutil
    import time

    from PIL import Image

    if shutil.which("Xvfb") is None or shutil.which("import") is None:
        pytest.skip(
            "Xvfb or ImageMagick's `import` is not installed (apt-get install xvfb imagemagick)"
        )
    display = ":88"  # a number no desktop takes (tests/video/test_viewer.py takes :87)
    server = subprocess.Popen(
        ["Xvfb", display, "-screen", "0", "800x600x24", "-nolisten", "tcp"],
        stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
    )  # fmt: skip
    try:
        for _ in range(100):  # until it listens (at most 10 s)
            if os.path.exists(f"/tmp/.X11-unix/X{display[1:]}"):
                break
            time.sleep(0.1)
        env = {k: v for k, v in os.environ.items() if k not in ("MUJOCO_GL", "WAYLAND_DISPLAY")}
        env["DISPLAY"] = display
        shown = None
        with subprocess.Popen(
            [sys.executable, "-c", HUMAN], env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
            text=True,
        ) as viewer:  # fmt: skip
            assert viewer.stdout is not None
            for _ in viewer.stdout:  # a screenshot after each step, while the window is open
                shot = tmp_path / "screen.png"
                taken = subprocess.run(
                    ["import", "-display", display, "-window", "root", str(shot)],
                    capture_output=True,
                )
                if taken.returncode == 0 and shown is None:
                    image = np.asarray(Image.open(shot).convert("RGB"))
                    # An empty X screen is one colour; the viewer's scene is many.
                    if len(np.unique(image.reshape(-1, 3), axis=0)) > 50:
                        shown = image
            err = viewer.stderr.read() if viewer.stderr else ""
        assert viewer.returncode == 0, err
        assert shown is not None
    finally:
        server.terminate()
        server.wait()
