"""A goal-conditioned policy of sim/envs' goal environments (PlayroomGoalEnv: a reinforcement-
learning baseline, such as stable-baselines3's SAC trained with hindsight relabelling) as an
actor of the measures (actors.py), one policy per toy, each trained on that toy's goals.

A test is asked as the environment asks: the observation is what `PlayroomGoalEnv.reset` gives
in the test's scene, the context then the feedback of no movement yet (zeros), the toy where
it lies as the achieved goal; the desired goal is the end point of the measure's goal
trajectory (the toy at the arm's base, (0, 0): the position the toy goals are of). The policy's
action is read as the environment reads it (`a[0] < 0`: the arm, else the voice). The measure's
error is the distance of the toy's whole 10D trajectory to the goal's (evaluation.py), as for
every learner: the policy is only ever asked for its end point.

Anything with stable-baselines3's `predict(observation, deterministic=True)` is a policy here:
this module imports no reinforcement-learning library.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any, Protocol

import numpy as np

from experiments.measure.actors import Choice
from models.layout import BLOCK_DIM, N_SAMPLES, SENSORY_DIM, TOYS, context_indices
from sim.envs.gym_env import SPACE_DTYPE, _motor_command

DictObs = dict[str, np.ndarray]


class GoalPolicy(Protocol):
    def predict(self, observation: DictObs, deterministic: bool = False) -> tuple[Any, Any]:
        """(action, state), as stable-baselines3's models answer."""
        ...


def goal_end(goal: np.ndarray) -> np.ndarray:
    """(2,) the last sample (x, y) of a 10D trajectory, 5 x then 5 y: a position goal of the
    goal environments (sim/envs/goals.py reads an achieved one from the same samples)."""
    return np.array([goal[N_SAMPLES - 1], goal[BLOCK_DIM - 1]])


def observation_of(toy: int, context: np.ndarray, goal: np.ndarray) -> DictObs:
    """PlayroomGoalEnv's observation at the start of an episode in the scene of `context`, with
    the end of `goal` (the measure's 10D trajectory of toy `toy`, 1-3) as the desired goal."""
    context = np.asarray(context, dtype=np.float64)
    return {
        "observation": np.concatenate([context, np.zeros(SENSORY_DIM)]).astype(SPACE_DTYPE),
        "achieved_goal": context[list(context_indices(TOYS[toy - 1]))].astype(SPACE_DTYPE),
        "desired_goal": goal_end(goal).astype(SPACE_DTYPE),
    }


class PolicyActor:
    """`policies[toy]`, toy 1-3, asked deterministically (see the module's docstring)."""

    def __init__(self, policies: Mapping[int, GoalPolicy]) -> None:
        missing = [t for t in range(1, len(TOYS) + 1) if t not in policies]
        if missing:
            raise ValueError(f"a policy for each toy 1-{len(TOYS)} is needed: none for {missing}")
        self.policies = dict(policies)

    def choose(self, toy: int, context: np.ndarray, goal: np.ndarray) -> Choice:
        observation = observation_of(toy, context, goal)
        action, _ = self.policies[toy].predict(observation, deterministic=True)
        # The environment's own reading of an action (and its one-line refusal of a bad one).
        space, command = _motor_command(np.asarray(action).reshape(-1))
        return Choice(space, command)
