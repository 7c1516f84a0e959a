"""The playroom as a dm_env environment at the level of the study's iterations: one step is one
arm command (21 parameters) or one voice command (28), as the study's agent acts.

The action is a dict, dm_env's nested form for a choice plus its parameters:
`{"motor_space": 0 (arm) or 1 (voice), "arm": (21,) in [-1, 1], "voice": (28,) in [-1, 1]}`.
The command of the motor space not chosen is ignored and may be left out, but is checked when
given, as the Gymnasium form checks its whole action; `motor_space` may also be its name ("arm",
"voice").

The observation is a dict: `context` (10,), the stick handle, toy1-3 and caregiver x, y before
the next command (models/layout.py); `feedback` (60,), the last movement's sensory feedback
(hand, stick, toy1-3, sound; zeros before the first movement); `events` (10,), how many events
of each kind of sim/events.py (`EVENT_KINDS`, in that order: grasps, catches with the stick,
moves, words recognised and said, ...) the last movement had. The events themselves, with their
objects, steps and words, are `env.last_feedback.events`; the room is `env.room`.

Between iterations the room places the toys and moves the caregiver as in the study
(`Playroom.act`). There is no reward (the study's agent sets its own goals): every step after
FIRST has reward 0.0, discount 1.0. An episode is `iterations` commands (the study's run, 80000,
by default) and ends with a LAST step, a truncation (discount 1.0); the next `step` starts a new
episode, as `reset()` does.

Seeds: the first episode is the room of `seed`, the world of a trial of that seed; `reset(seed=s)`
starts the room of seed s; `reset()` with no seed starts a room whose seed is drawn from a
generator seeded by the last seed given (`episode_seed` says which).
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import dm_env
import numpy as np
from dm_env import specs

from models.layout import ARM_DIM, CONTEXT_DIM, MOTOR_DIMS, MOTOR_SPACES, SENSORY_DIM, VOICE_DIM
from models.world import Feedback
from sim.config import WorldConfig
from sim.envs.actions import checked_numbers
from sim.envs.world import (
    EVENT_KINDS,
    SEED_BOUND,
    STUDY_ITERATIONS,
    ObservationBounds,
    checked_seed,
    observed,
    room_settings,
)
from sim.grasping.names import DEFAULT_GRASP
from sim.playroom import Playroom
from sim.vocal.config import DEFAULT_VOICE, VoiceConfig

MOTOR_SPACE = "motor_space"
ACTION_KEYS = (MOTOR_SPACE, *MOTOR_SPACES)
ACTION_FORM = "{'motor_space': 0 (arm) or 1 (voice), 'arm': (21,), 'voice': (28,)}"


class PlayroomMovementEnv(dm_env.Environment):
    """The playroom, one step per arm or voice command (see the module's docstring).

    grasp: 'kinematic' (the default) or 'physical'; preset ('study', the default, or 'project')
    or config (a whole `WorldConfig`); voice: the vocal tract, 'vtl' or 'diva' (the config's,
    VocalTractLab by default, when None); voice_config: the voice's numbers; iterations: commands
    per episode (None: episodes never end); seed: the first episode's room.
    """

    def __init__(
        self,
        grasp: str = DEFAULT_GRASP,
        preset: str | None = None,
        config: WorldConfig | None = None,
        voice: str | None = None,
        voice_config: VoiceConfig = DEFAULT_VOICE,
        iterations: int | None = STUDY_ITERATIONS,
        seed: int = 0,
    ) -> None:
        self.settings = room_settings(grasp, preset, config, voice, voice_config, iterations)
        self._next_seed: int | None = checked_seed(seed)
        self._seeds = np.random.default_rng(self._next_seed)
        self.episode_seed = self._next_seed
        self.room: Playroom = self.settings.room(self._next_seed)
        self.bounds = ObservationBounds.of(self.room)
        self.last_feedback: Feedback | None = None
        self._needs_reset = True

    # dm_env interface ---------------------------------------------------------------------
    def reset(self, seed: int | None = None) -> dm_env.TimeStep:
        """A new episode in a new room: of `seed` if given (see the module's docstring)."""
        if seed is not None:
            room_seed = checked_seed(seed)
            self._seeds = np.random.default_rng(room_seed)
        elif self._next_seed is not None:
            room_seed = self._next_seed
        else:
            room_seed = int(self._seeds.integers(SEED_BOUND))
        self._next_seed = None
        self.room = self.settings.room(room_seed)
        self.episode_seed = room_seed
        self.last_feedback = None
        self._needs_reset = False
        return dm_env.restart(observed(self.room, None, self.bounds))

    def step(self, action: Mapping[str, Any]) -> dm_env.TimeStep:
        """One command; the first step of an episode (a fresh environment, or after LAST)
        resets instead and ignores the action, as dm_env requires. ValueError for an action
        that is not of the action spec, before anything moves."""
        if self._needs_reset:
            return self.reset()
        motor_space, command = motor_command(action)
        self.last_feedback = self.room.act(motor_space, command)
        observation = observed(self.room, self.last_feedback, self.bounds)
        end = self.settings.iterations
        if end is not None and self.room.iteration >= end:
            self._needs_reset = True
            return dm_env.truncation(0.0, observation)
        return dm_env.transition(0.0, observation)

    def action_spec(self) -> dict[str, specs.Array]:
        return {
            MOTOR_SPACE: specs.DiscreteArray(len(MOTOR_SPACES), name=MOTOR_SPACE),
            "arm": specs.BoundedArray((ARM_DIM,), np.float64, -1.0, 1.0, name="arm"),
            "voice": specs.BoundedArray((VOICE_DIM,), np.float64, -1.0, 1.0, name="voice"),
        }

    def observation_spec(self) -> dict[str, specs.Array]:
        b = self.bounds
        return {
            "context": specs.BoundedArray(
                (CONTEXT_DIM,), np.float64, -b.context, b.context, name="context"
            ),
            "feedback": specs.BoundedArray(
                (SENSORY_DIM,), np.float64, -b.feedback, b.feedback, name="feedback"
            ),
            "events": specs.BoundedArray(
                (len(EVENT_KINDS),), np.int64, 0, np.iinfo(np.int64).max, name="events"
            ),
        }


def motor_command(action: object) -> tuple[str, Any]:
    """(motor space, its command) of a dict action; ValueError in one line naming what is
    wrong (sim/envs/actions.py: real finite numbers of the command's shape in [-1, 1])."""
    if not isinstance(action, Mapping):
        raise ValueError(f"the action must be a dict {ACTION_FORM}, got {type(action).__name__}")
    unknown = sorted(map(str, set(action) - set(ACTION_KEYS)))
    if unknown:
        raise ValueError(f"unknown action keys {unknown}: the action is {ACTION_FORM}")
    if MOTOR_SPACE not in action:
        raise ValueError(f"the action has no 'motor_space': it is {ACTION_FORM}")
    space = action[MOTOR_SPACE]
    if isinstance(space, str):
        name = space
    else:
        index = np.asarray(space)
        if index.ndim != 0 or index.dtype.kind not in "iu" or not 0 <= index < len(MOTOR_SPACES):
            raise ValueError(f"motor_space must be 0 (arm), 1 (voice) or a name, got {space!r}")
        name = MOTOR_SPACES[int(index)]
    if name not in MOTOR_SPACES:
        raise ValueError(f"unknown motor space {name!r}: one of {MOTOR_SPACES}")
    if name not in action:
        raise ValueError(f"the action chooses the {name} but holds no {name!r} command")
    # Every command given is checked, the one not chosen included, as the Gymnasium form checks
    # its whole flat action: a NaN there is a fault of the learner in either form.
    commands = {
        space: checked_numbers(action[space], MOTOR_DIMS[space], f"the {space} command")
        for space in MOTOR_SPACES
        if space in action
    }
    return name, commands[name]
