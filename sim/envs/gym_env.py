"""The playroom as a Gymnasium environment, registered as "Playroom-v0" by `import sim.envs`
(or `gymnasium.make("sim.envs:Playroom-v0")`, which imports it): the dm_env environment of
sim/envs/dm_env_movement.py, with flat Box spaces for the libraries that need them.

Action: Box [-1, 1]^50. a[0] chooses the motor space (below 0: arm, else voice), a[1:22] is
the arm command (21), a[22:50] the voice command (28); the command not chosen moves nothing
but is checked as the chosen one is (sim/envs/actions.py).
Observation: Box (70,), the context (10) then the last movement's feedback (60; zeros after
reset), bounded by the table (m) and SOUND_BOUND. `info` holds the movement's `motor_space`,
its `events` (dicts: kind, step, obj, by, word), `event_counts` (one per EVENT_KINDS), the
room's `iteration` and the episode's `seed`.

Reward 0.0 always (no extrinsic reward), terminated always False; truncated is True at the
`iterations`-th command (the study's 80000 by default), after which step() wants a reset().
`reset(seed=s)` starts the room of seed s, the world of a trial of that seed; `reset()` a room
of a seed drawn from `np_random`.

Render modes (sim/envs/rendering.py): "rgb_array", `render()` returns the room as it is now,
(height, width, 3) uint8 from the MJCF's camera `camera` ("top" or "hand_view") at
`render_size` (width, height), offscreen with the GL backend MUJOCO_GL names (EGL when unset);
"human", MuJoCo's viewer shows the room after every reset and step (it needs a display). With
no render mode nothing loads a GL library. Rendering reads the room and changes nothing of it;
videos of a trial, with sound, are `playroom render`'s.
"""

from __future__ import annotations

from typing import Any

import gymnasium
import mujoco
import numpy as np
from gymnasium import logger, spaces

from models.layout import ARM_DIM, VOICE_DIM
from sim.config import WorldConfig
from sim.envs.actions import checked_numbers
from sim.envs.dm_env_movement import PlayroomMovementEnv
from sim.envs.rendering import (
    DEFAULT_SIZE,
    OffscreenRenderer,
    RenderError,
    Viewer,
    checked_view,
    display_missing,
)
from sim.envs.world import SEED_BOUND, STUDY_ITERATIONS, checked_seed, event_dicts
from sim.grasping.names import DEFAULT_GRASP
from sim.task import ARM, VOICE
from sim.vocal.config import DEFAULT_VOICE, VoiceConfig

# Where each part of the flat action lies.
SELECTOR = 0
ARM_PART = slice(1, 1 + ARM_DIM)
VOICE_PART = slice(ARM_PART.stop, ARM_PART.stop + VOICE_DIM)
ACTION_DIM = VOICE_PART.stop  # 50


class PlayroomGymEnv(gymnasium.Env[np.ndarray, np.ndarray]):
    """The playroom, one step per arm or voice command, in Gymnasium's form (see the module's
    docstring); the same keyword arguments as `PlayroomMovementEnv`, less the seed (given to
    `reset`)."""

    # One step is one movement of 50 control steps of 20 ms: a second of the room.
    metadata: dict[str, Any] = {"render_modes": ["human", "rgb_array"], "render_fps": 1}

    def __init__(
        self,
        grasp: str = DEFAULT_GRASP,
        preset: str | None = None,
        config: WorldConfig | None = None,
        voice: VoiceConfig = DEFAULT_VOICE,
        iterations: int = STUDY_ITERATIONS,
        render_mode: str | None = None,
        render_size: tuple[int, int] = DEFAULT_SIZE,
        camera: str = "top",
    ) -> None:
        if render_mode is not None and render_mode not in self.metadata["render_modes"]:
            raise ValueError(
                f"unknown render_mode {render_mode!r}: one of {self.metadata['render_modes']} "
                "or None"
            )
        if render_mode == "human" and display_missing() is not None:
            raise RenderError(display_missing())
        self.render_mode = render_mode
        self.movement_env = PlayroomMovementEnv(grasp, preset, config, voice, iterations)
        self.render_size = checked_view(
            self.movement_env.room.physics.model.ptr, render_size, camera
        )
        self.camera = camera
        # Made on the first render, for the episode's room (each episode is a new Playroom).
        self._renderer: OffscreenRenderer | Viewer | None = None
        self._rendered_room: Any = None
        self._render_data: Any = None
        b = self.movement_env.bounds
        high = np.concatenate([b.context, b.feedback])
        self.action_space = spaces.Box(-1.0, 1.0, (ACTION_DIM,), np.float64)
        self.observation_space = spaces.Box(-high, high, dtype=np.float64)
        self._state = "unreset"  # unreset | running | truncated

    def reset(
        self, *, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[np.ndarray, dict[str, Any]]:
        if seed is not None:
            seed = checked_seed(seed)
        if options:
            raise ValueError(f"reset takes no options, got {sorted(options)}")
        super().reset(seed=seed)
        room_seed = int(self.np_random.integers(SEED_BOUND)) if seed is None else seed
        timestep = self.movement_env.reset(seed=room_seed)
        self._state = "running"
        info = {"seed": room_seed, "iteration": 0, "events": [], "event_counts": _counts(timestep)}
        if self.render_mode == "human":
            self.render()
        return _flat(timestep.observation), info

    def step(self, action: np.ndarray) -> tuple[np.ndarray, float, bool, bool, dict[str, Any]]:
        if self._state != "running":
            raise RuntimeError(
                "call reset() first"
                if self._state == "unreset"
                else f"the episode ended after {self.movement_env.settings.iterations} "
                "iterations (truncated): call reset()"
            )
        motor_space, command = _motor_command(action)
        timestep = self.movement_env.step({"motor_space": motor_space, motor_space: command})
        feedback = self.movement_env.last_feedback
        assert feedback is not None  # a step after reset acts
        if timestep.last():
            self._state = "truncated"
        info = {
            "motor_space": motor_space,
            "events": event_dicts(feedback),
            "event_counts": _counts(timestep),
            "iteration": self.movement_env.room.iteration,
            "seed": self.movement_env.episode_seed,
        }
        if self.render_mode == "human":
            self.render()
        return _flat(timestep.observation), 0.0, False, timestep.last(), info

    def render(self) -> np.ndarray | None:
        """The room as it is now: a frame under "rgb_array", shown in the viewer under "human"
        (None); with no render mode, a warning and None, as Gymnasium's own environments do."""
        if self.render_mode is None:
            logger.warn(
                "render() without a render mode renders nothing: make the environment with "
                'render_mode="rgb_array" or "human"'
            )
            return None
        room = self.movement_env.room
        model = room.physics.model.ptr
        if room is not self._rendered_room:  # a new episode's room: a new model and data
            self.close()
            # The frames come from a copy of the room's state, made consistent by mj_forward
            # there: the room's own MjData is never computed on, so rendering changes no bit of
            # the world.
            self._render_data = mujoco.MjData(model)
            if self.render_mode == "rgb_array":
                self._renderer = OffscreenRenderer(model, self.render_size, self.camera)
            else:
                self._renderer = Viewer(model, self._render_data)
            self._rendered_room = room
        data = room.physics.data.ptr
        self._render_data.qpos[:] = data.qpos
        self._render_data.mocap_pos[:] = data.mocap_pos
        self._render_data.mocap_quat[:] = data.mocap_quat
        mujoco.mj_forward(model, self._render_data)
        if isinstance(self._renderer, OffscreenRenderer):
            return self._renderer.render(self._render_data)
        assert self._renderer is not None
        self._renderer.show()
        return None

    def close(self) -> None:
        """Frees the renderer or closes the viewer (an EGL context left to the garbage
        collector at exit prints errors)."""
        if self._renderer is not None:
            self._renderer.close()
        self._renderer = self._rendered_room = self._render_data = None


def _motor_command(action: object) -> tuple[str, np.ndarray]:
    """(motor space, its command) of a flat action; ValueError in one line if the action is not
    of the action space, the part not chosen included (sim/envs/actions.py)."""
    a = checked_numbers(action, ACTION_DIM, "the action")
    if a[SELECTOR] < 0:
        return ARM, a[ARM_PART].copy()
    return VOICE, a[VOICE_PART].copy()


def _flat(observation: dict[str, np.ndarray]) -> np.ndarray:
    return np.concatenate([observation["context"], observation["feedback"]])


def _counts(timestep: Any) -> np.ndarray:
    return timestep.observation["events"].copy()
