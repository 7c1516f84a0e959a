"""The playroom as a Gymnasium environment, registered as "Playroom-v0" by `import sim.envs`
(or `gymnasium.make("sim.envs:Playroom-v0")`, which imports it): the dm_env environment of
sim/envs/dm_env_movement.py, with flat Box spaces for the libraries that need them.

Action: Box [-1, 1]^50. a[0] chooses the motor space (below 0: arm, else voice), a[1:22] is
the arm command (21), a[22:50] the voice command (28); the command not chosen is ignored.
Observation: Box (70,), the context (10) then the last movement's feedback (60; zeros after
reset), bounded by the table (m) and SOUND_BOUND. `info` holds the movement's `motor_space`,
its `events` (dicts: kind, step, obj, by, word), `event_counts` (one per EVENT_KINDS), the
room's `iteration` and the episode's `seed`.

Reward 0.0 always (no extrinsic reward), terminated always False; truncated is True at the
`iterations`-th command (the study's 80000 by default), after which step() wants a reset().
`reset(seed=s)` starts the room of seed s, the world of a trial of that seed; `reset()` a room
of a seed drawn from `np_random`. No render modes: videos of a room are `playroom render`'s.
"""

from __future__ import annotations

from typing import Any

import gymnasium
import numpy as np
from gymnasium import spaces

from models.layout import ARM_DIM, VOICE_DIM
from sim.commands import RANGE_TOLERANCE
from sim.config import WorldConfig
from sim.envs.dm_env_movement import PlayroomMovementEnv
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

    metadata: dict[str, Any] = {"render_modes": []}

    def __init__(
        self,
        grasp: str = DEFAULT_GRASP,
        preset: str | None = None,
        config: WorldConfig | None = None,
        voice: VoiceConfig = DEFAULT_VOICE,
        iterations: int = STUDY_ITERATIONS,
        render_mode: str | None = None,
    ) -> None:
        if render_mode is not None:
            raise ValueError(f"render_mode {render_mode!r}: this environment renders nothing")
        self.render_mode = render_mode
        self.movement_env = PlayroomMovementEnv(grasp, preset, config, voice, iterations)
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
        return _flat(timestep.observation), 0.0, False, timestep.last(), info


def _motor_command(action: object) -> tuple[str, np.ndarray]:
    """(motor space, its command) of a flat action; ValueError in one line if the action is not
    of the action space (the part not chosen included)."""
    try:
        a = np.asarray(action, dtype=np.float64)
    except (TypeError, ValueError) as exc:
        raise ValueError(f"the action must be {ACTION_DIM} numbers in [-1, 1]: {exc}") from None
    if a.shape != (ACTION_DIM,):
        raise ValueError(f"the action must have shape ({ACTION_DIM},), got {a.shape}")
    if not np.isfinite(a).all():
        bad = np.flatnonzero(~np.isfinite(a)).tolist()
        raise ValueError(f"the action contains NaN or inf at indices {bad}")
    if np.abs(a).max() > 1.0 + RANGE_TOLERANCE:
        raise ValueError(f"the action must lie in [-1, 1], max |value| is {np.abs(a).max():.6g}")
    if a[SELECTOR] < 0:
        return ARM, a[ARM_PART].copy()
    return VOICE, a[VOICE_PART].copy()


def _flat(observation: dict[str, np.ndarray]) -> np.ndarray:
    return np.concatenate([observation["context"], observation["feedback"]])


def _counts(timestep: Any) -> np.ndarray:
    return timestep.observation["events"].copy()
