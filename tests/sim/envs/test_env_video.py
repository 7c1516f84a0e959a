"""Frames of the Gymnasium environment as Gymnasium's video tools take them: RecordVideo's, one
after each reset and step, each showing where the step's movement ended; "rgb_array_list"'s,
every control step of the movement at its own rate, which Gymnasium's `save_video` writes as the
movement; and a renderer left open at exit goes without GL errors."""

from __future__ import annotations

import os
import subprocess
import sys
import types

import gymnasium
import imageio_ffmpeg
import mujoco
import numpy as np
import pytest
from gymnasium.wrappers import RecordVideo
from rl_extra import require
from scripted import Waypoint, arm_command_through

from experiments.video.overlay import CameraView
from sim.envs import GYM_ID, PlayroomGymEnv
from sim.envs.rendering import BACKENDS, DEFAULT_BACKEND

SIZE = (320, 240)
# Where the hand ends, away from the arm at rest (along +y) and from the toys of seed 0.
HAND_END = (0.35, -0.2)
NEAR = 6  # px (about 6 cm here): the arm's last segment reaches the hand's centre


@pytest.fixture
def recorded_clips(monkeypatch):
    """RecordVideo itself, its MoviePy writer (not a dependency here) replaced by one that keeps
    each clip's frames."""
    clips: list[list[np.ndarray]] = []

    class Clip:
        def __init__(self, frames: list[np.ndarray], fps: float) -> None:
            self.frames = list(frames)

        def write_videofile(self, path: str, logger: object = None) -> None:
            clips.append(self.frames)

    for name in ("moviepy", "moviepy.video", "moviepy.video.io"):
        monkeypatch.setitem(sys.modules, name, types.ModuleType(name))
    writer = types.ModuleType("moviepy.video.io.ImageSequenceClip")
    writer.ImageSequenceClip = Clip  # type: ignore[attr-defined]
    monkeypatch.setitem(sys.modules, writer.__name__, writer)
    return clips


def _arm_action(config) -> np.ndarray:
    m, error = arm_command_through([Waypoint(25, (0.3, 0.3)), Waypoint(50, HAND_END)], config)
    assert error < 0.02
    return np.r_[-1.0, m, np.zeros(28)].astype(np.float32)


def _arm_near(frame: np.ndarray, uv: np.ndarray) -> bool:
    """Whether the arm's blue (models/playroom.xml, material "arm") lies within NEAR px."""
    u, v = np.round(uv).astype(int)
    patch = frame[v - NEAR : v + NEAR + 1, u - NEAR : u + NEAR + 1].astype(int)
    r, g, b = patch[..., 0], patch[..., 1], patch[..., 2]
    return bool(((b - r > 60) & (g - r > 20) & (b > g)).any())


@pytest.mark.parametrize("grasp", ["kinematic", "physical"])
def test_a_recorded_video_shows_the_arm_where_its_movement_took_it(recorded_clips, tmp_path, grasp):
    env = gymnasium.make(GYM_ID, grasp=grasp, render_mode="rgb_array", render_size=SIZE)
    env = RecordVideo(
        env, str(tmp_path / "videos"), episode_trigger=lambda _: True, disable_logger=True
    )
    env.reset(seed=0)
    room = env.unwrapped.movement_env.room
    env.step(_arm_action(room.config))
    hand = env.unwrapped.movement_env.last_feedback.positions[-1, 0]  # after the last step
    model, data = room.physics.model.ptr, room.physics.data.ptr
    height = data.geom_xpos[mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_GEOM, "hand"), 2]
    uv = CameraView.of(model, data, "top", *SIZE).project(np.r_[hand, height])[0]
    env.close()
    (frames,) = recorded_clips  # one frame after the reset, one after the step
    at_reset, after_step = frames
    assert np.linalg.norm(hand - HAND_END) < 0.02
    assert _arm_near(after_step, uv) and not _arm_near(at_reset, uv)


@pytest.mark.slow  # MoviePy (the `rl` extra) encodes the clip through ffmpeg
def test_recordvideos_own_writer_files_a_clip_of_the_arm_moving(tmp_path):
    require("moviepy")

    env = gymnasium.make(GYM_ID, grasp="physical", render_mode="rgb_array", render_size=SIZE)
    env = RecordVideo(
        env, str(tmp_path / "videos"), episode_trigger=lambda _: True, disable_logger=True
    )
    env.reset(seed=0)
    room = env.unwrapped.movement_env.room
    env.step(_arm_action(room.config))
    hand = env.unwrapped.movement_env.last_feedback.positions[-1, 0]
    model, data = room.physics.model.ptr, room.physics.data.ptr
    height = data.geom_xpos[mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_GEOM, "hand"), 2]
    uv = CameraView.of(model, data, "top", *SIZE).project(np.r_[hand, height])[0]
    env.close()
    (clip,) = (tmp_path / "videos").glob("*.mp4")
    reader = imageio_ffmpeg.read_frames(str(clip))  # the MP4 file, decoded
    width, height = next(reader)["size"]
    frames = [np.frombuffer(f, np.uint8).reshape(height, width, 3) for f in reader]
    assert (width, height) == SIZE and len(frames) == 2
    assert _arm_near(frames[1], uv) and not _arm_near(frames[0], uv)


def test_a_movements_frames_come_as_a_list_one_a_control_step_at_its_rate():
    env = gymnasium.make(GYM_ID, render_mode="rgb_array_list", render_size=SIZE)
    assert env.metadata["render_fps"] == 50  # a control step lasts 20 ms: real time
    assert gymnasium.make(GYM_ID, render_mode="rgb_array").metadata["render_fps"] == 1
    env.reset(seed=0)
    room = env.unwrapped.movement_env.room
    env.step(_arm_action(room.config))
    frames = env.render()
    assert env.render() == []  # each frame is given once
    assert len(frames) == 1 + 50  # after the reset, then after each control step
    assert all(f.shape == (SIZE[1], SIZE[0], 3) and f.dtype == np.uint8 for f in frames)
    # The hand where the feedback saw it mid-movement (step 25) and at its end (step 50).
    hand = env.unwrapped.movement_env.last_feedback.positions[:, 0]  # row k - 1: after step k
    model, data = room.physics.model.ptr, room.physics.data.ptr
    height = data.geom_xpos[mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_GEOM, "hand"), 2]
    view = CameraView.of(model, data, "top", *SIZE)
    mid, end = (view.project(np.r_[hand[k - 1], height])[0] for k in (25, 50))
    assert np.linalg.norm(hand[-1] - HAND_END) < 0.02
    assert _arm_near(frames[25], mid) and not _arm_near(frames[0], mid)
    assert _arm_near(frames[50], end) and not _arm_near(frames[25], end)
    env.close()


@pytest.mark.slow  # MoviePy (the `rl` extra) encodes the clip through ffmpeg
def test_gymnasiums_save_video_writes_the_movement_in_real_time(tmp_path):
    require("moviepy")
    from gymnasium.utils.save_video import save_video

    env = gymnasium.make(GYM_ID, render_mode="rgb_array_list", render_size=SIZE)
    env.reset(seed=0)
    env.step(_arm_action(env.unwrapped.movement_env.room.config))
    save_video(env.render(), str(tmp_path), fps=env.metadata["render_fps"], name_prefix="arm")
    env.close()
    (clip,) = tmp_path.glob("arm*.mp4")
    reader = imageio_ffmpeg.read_frames(str(clip))
    meta = next(reader)
    assert meta["size"] == SIZE and meta["fps"] == 50
    frames = [np.frombuffer(f, np.uint8).reshape(SIZE[1], SIZE[0], 3).astype(int) for f in reader]
    # The reset's frame and the movement's 50, a second of the room; MoviePy 1.0.3 ends a clip
    # with its last frame once more.
    assert len(frames) == 52 and np.abs(frames[-1] - frames[-2]).mean() < 0.1


def test_a_frame_after_a_step_made_before_any_render_says_what_it_shows():
    env = PlayroomGymEnv(iterations=10, render_mode="rgb_array", render_size=SIZE)
    env.reset(seed=0)
    env.step(_arm_action(env.movement_env.room.config))
    with pytest.warns(UserWarning, match="render after reset\\(\\) to see them all"):
        env.render()
    env.close()


# Never closed: one dropped while the program runs, one left to the end.
NOT_CLOSED = f"""
import gc
import gymnasium
for _ in range(2):
    env = gymnasium.make("sim.envs:{GYM_ID}", render_mode="rgb_array", render_size={SIZE})
    env.reset(seed=0)
    env.render()
    gc.collect()
print("rendered", flush=True)
"""


def test_environments_left_open_exit_without_gl_errors():
    # The backend the suite renders with (tests/video/conftest.py): MUJOCO_GL's, else EGL.
    chosen = os.environ.get("MUJOCO_GL", "").strip().lower()
    backend = chosen if chosen in BACKENDS else DEFAULT_BACKEND
    env = dict(os.environ, MUJOCO_GL=backend)
    result = subprocess.run(
        [sys.executable, "-c", NOT_CLOSED], env=env, capture_output=True, text=True
    )
    if result.stdout == "" and "RenderError" in result.stderr:
        pytest.skip(f"MUJOCO_GL={backend} cannot render here: {result.stderr.splitlines()[-1]}")
    assert (result.returncode, result.stdout, result.stderr) == (0, "rendered\n", "")
