"""The motor spaces a goal environment acts in (sim/envs/goal_env.py, its `motor` argument): the
arm's 21 numbers, the voice's 28, or both behind PlayroomGymEnv's switch `a[0]` (50), and which
of them can reach each goal. Each is read into PlayroomGymEnv's flat action, which steps the room.

A goal reached by one motor space gets that space alone by default: the other's numbers would
move nothing toward it, and a learner relabelling its goals (hindsight) would be rewarded for the
space that leaves the object where it lies (docs/rl-baseline.md).
"""

from __future__ import annotations

import numpy as np

from models.layout import ARM_DIM, VOICE_DIM
from sim.envs.actions import checked_numbers
from sim.envs.goals import Goal
from sim.envs.gym_env import ACTION_DIM, ARM_PART, SELECTOR, VOICE_PART
from sim.task import ARM, VOICE

BOTH = "both"
MOTORS = (ARM, VOICE, BOTH)
# PlayroomGymEnv's switch `a[0]` for a command of one space (`a[0] < 0`: the arm, else the voice).
SWITCH = {ARM: -1.0, VOICE: 1.0}


def checked_motor(motor: object, goal: Goal) -> str:
    """The motor space `motor` names, the goal's own (`default_motor`) for None; ValueError in
    one line naming the choices."""
    if motor is None:
        return default_motor(goal)
    if not isinstance(motor, str) or motor not in MOTORS:
        raise ValueError(f"unknown motor {motor!r}: one of {', '.join(MOTORS)} (or None)")
    return motor


def default_motor(goal: Goal) -> str:
    """The motor space that reaches the goal: the voice for the agent's own sound (the study's
    model 10), the arm for the hand, the stick and a toy within reach (models 1-5; a toy in the
    study's ring 3, which only the caregiver brings nearer, is never drawn as a goal)."""
    return ARM if goal.is_position else VOICE


def action_size(motor: str) -> int:
    """How many numbers an action of the motor space has: 21, 28 or 50."""
    return {ARM: ARM_DIM, VOICE: VOICE_DIM, BOTH: ACTION_DIM}[motor]


def flat_action(motor: str, action: object) -> np.ndarray:
    """PlayroomGymEnv's (50,) action for an action of the motor space, checked first against
    the motor space's own size and range (the one-line ValueError of sim/envs/actions.py)."""
    numbers = checked_numbers(action, action_size(motor), "the action")
    if motor == BOTH:
        return numbers
    flat = np.zeros(ACTION_DIM)
    flat[SELECTOR] = SWITCH[motor]
    flat[ARM_PART if motor == ARM else VOICE_PART] = numbers
    return flat
