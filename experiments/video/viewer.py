"""`playroom view`: the room in MuJoCo's own interactive viewer (`mujoco.viewer.launch_passive`),
live, at the room's real pace (one control step is 20 ms of simulated time): a trial replayed
from its start (exactly, as videos replay it: experiments/video/replay.py), or random commands
in a new room. It needs a display; the OpenGL backend is GLFW (`gl.for_viewing`)."""

from __future__ import annotations

import contextlib
import os
import sys
import threading
import time
from collections.abc import Iterator
from typing import Any

import numpy as np

from experiments.run.trial_parts import fresh_trial_parts
from experiments.trial_dir.reading import open_for_reading
from models.layout import ARM_DIM, VOICE_DIM
from models.presets import DEFAULT_PRESET
from models.world import Feedback
from sim import Playroom
from sim.config import world_preset
from sim.movement import posed, posed_as
from sim.physics import CONTROL_SUBSTEPS, PlayroomPhysics


class ViewError(Exception):
    """What the user asked cannot be viewed; the message says why, in one line."""


def display_missing() -> str | None:
    """Why no window can open here (one line), or None where a display is set (macOS and
    Windows always have one)."""
    if sys.platform != "linux" or os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY"):
        return None
    return (
        "a display is needed (neither DISPLAY nor WAYLAND_DISPLAY is set); on a "
        "machine without one, film the trial instead: playroom render"
    )


class _Window:
    """MuJoCo's passive viewer of a copy of the room's physics (its own data: the room's is
    never touched by the window's thread), showing each control step of every movement from
    the movement's trace at `pace` x real time, and the room as it is between movements."""

    def __init__(self, room: Playroom, viewer: Any, shown: PlayroomPhysics, pace: float) -> None:
        self.room, self.viewer, self.shown = room, viewer, shown
        self.step_s = room.physics.model.opt.timestep * CONTROL_SUBSTEPS / pace
        room.tracing = True
        self._show_room()

    def act(self, motor_space: str, m: np.ndarray) -> Feedback:
        """The command acted in the room, its movement shown step by step."""
        feedback = self.room.act(motor_space, m)
        trace = self.room.last_trace
        assert trace is not None  # the room traces
        model, data = self.shown.model.ptr, self.shown.data.ptr
        clock = time.perf_counter()
        for step in range(1, len(trace.qpos)):
            if not self.viewer.is_running():  # closed: the movement ends unseen
                return feedback
            with self.viewer.lock():
                posed(model, data, trace, step)
            self.viewer.sync()
            clock += self.step_s
            time.sleep(max(0.0, clock - time.perf_counter()))
        self._show_room()
        return feedback

    def _show_room(self) -> None:
        source, data = self.room.physics.data.ptr, self.shown.data.ptr
        with self.viewer.lock():
            posed_as(self.shown.model.ptr, data, source.qpos, source.mocap_pos)
        self.viewer.sync()


# How long to wait for the viewer's window to close after the last iteration (s).
CLOSE_WAIT_S = 10


@contextlib.contextmanager
def _launch(room: Playroom, pace: float) -> Iterator[_Window]:
    """The passive viewer of a copy of the room, closed on leaving: its window's thread is
    waited for, since GLFW is terminated at exit and would pull the window from under a running
    thread (a segmentation fault at the command's end)."""
    import mujoco.viewer

    before = set(threading.enumerate())
    shown = room.physics.copy(share_model=True)
    handle = mujoco.viewer.launch_passive(
        shown.model.ptr, shown.data.ptr, show_left_ui=False, show_right_ui=False
    )
    window_threads = set(threading.enumerate()) - before
    try:
        yield _Window(room, handle, shown, pace)
    finally:
        handle.close()
        for thread in window_threads:
            thread.join(CLOSE_WAIT_S)


def view_random(grasp: str, seed: int, iterations: int, voice: str, pace: float = 1.0) -> int:
    """Random commands (arm or voice, 1/2 each) in a new room, shown live; returns how many
    were shown (fewer if the window was closed)."""
    room = Playroom(grasp=grasp, seed=seed, config=world_preset(DEFAULT_PRESET, voice=voice))
    rng = np.random.default_rng([seed, 1])  # a stream apart from the room's own
    with _launch(room, pace) as window:
        for shown in range(iterations):
            if not window.viewer.is_running():
                return shown
            space = "arm" if rng.random() < 0.5 else "voice"
            window.act(space, rng.uniform(-1.0, 1.0, ARM_DIM if space == "arm" else VOICE_DIM))
    return iterations


def view_trial(trial_dir: str | os.PathLike, start: int, count: int, pace: float = 1.0) -> int:
    """A trial's iterations `start` .. `start + count - 1`, shown live after replaying the
    earlier ones unseen (the replay is exact: the same agent, the same room, the same draws);
    returns how many were shown."""
    trial = open_for_reading(trial_dir)
    if not trial.config_path.is_file():
        raise ViewError(trial.no_trial_line())
    config = trial.config()
    total = int(config["trial"]["iterations"])
    if not 0 <= start < total:
        raise ViewError(f"--from {start} is out of range: the trial has 0..{total - 1}")
    agent, room = fresh_trial_parts(config)
    for _ in range(start):
        agent.play(room)
    with _launch(room, pace) as window:
        for shown in range(min(count, total - start)):
            if not window.viewer.is_running():
                return shown
            agent.play(room, lambda proposal: window.act(proposal.motor_space, proposal.m))
    return min(count, total - start)
