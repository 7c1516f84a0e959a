"""One goal environment for the three toys: the toy is part of the goal, so that one
goal-conditioned policy learns all three from every movement (the race with Model Babbling,
docs/rl-race.md), as Model Babbling's one memory does. `PlayroomToysGoalEnv`'s docstring says
what differs from the one-toy environments (sim/envs/goal_env.py), which it reuses whole.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from gymnasium import spaces

from models.layout import TOYS
from sim.envs import goals
from sim.envs.goal_env import DESIRED_GOAL, SPARSE, DictObs, PlayroomGoalEnv
from sim.envs.gym_env import SPACE_DTYPE

# A goal's numbers: which toy (one-hot, in the order of models.layout.TOYS), then its x, y.
TOY_PART = slice(0, len(TOYS))
POSITION_PART = slice(len(TOYS), len(TOYS) + 2)
GOAL_DIM = POSITION_PART.stop


class PlayroomToysGoalEnv(PlayroomGoalEnv):
    """## Description

    PlayroomToyGoal-v1 (PlayroomGoalEnv with a toy's goal: the arm alone, one movement an
    episode, the sparse reward by default, desired goals never met at reset, the ring in
    `info`) with the toy drawn at each `reset`, toy1, toy2 or toy3 with equal chance, from the
    environment's `np_random` before the toy's point. Every keyword of PlayroomGoalEnv but
    `goal` is taken, with the same meaning.

    ## Goals

    Box((5,), float32): which toy, one-hot in the order toy1, toy2, toy3 (each 0 or 1), then the
    toy's x, y (m, within the table's half-size), for both `achieved_goal` and `desired_goal`.
    The achieved goal names the episode's toy and where it lies (after a movement: at the
    movement's last sample). The reward is the one-toy environment's on the positions, and a
    failure (-1, or minus the distance plus the one-hot's) when the toys differ;
    `compute_reward` takes single goals or batches, as hindsight relabelling calls it.
    `info["toy"]` names the episode's toy. `reset(options={"desired_goal": g})` sets the goal
    to g, a one-hot then a point (refused in one line otherwise).

    ## Version History

    * v1: initial version, PlayroomToysGoal-v1 and PlayroomToysGoalPhysical-v1 (the physical
      grasp), goal ids v1's environment for the three toys.
    """

    def __init__(self, **kwargs: Any) -> None:
        if "goal" in kwargs:
            raise ValueError("the toys' environment draws its toy: give no goal")
        super().__init__(TOYS[0], **kwargs)
        bound = self.goal_space.high[0]
        low = np.array([0.0] * len(TOYS) + [-bound, -bound], dtype=SPACE_DTYPE)
        high = np.array([1.0] * len(TOYS) + [bound, bound], dtype=SPACE_DTYPE)
        self.goal_space = spaces.Box(low, high, dtype=SPACE_DTYPE)
        self.observation_space = spaces.Dict(
            {
                "observation": self.playroom.observation_space,
                "achieved_goal": self.goal_space,
                DESIRED_GOAL: spaces.Box(low, high, dtype=SPACE_DTYPE),
            }
        )

    def reset(
        self, *, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[DictObs, dict[str, Any]]:
        observation, info = super().reset(seed=seed, options=options)
        info["toy"] = self.goal.name
        return observation, info

    def step(self, action: np.ndarray) -> tuple[DictObs, float, bool, bool, dict[str, Any]]:
        observation, reward, terminated, truncated, info = super().step(action)
        info["toy"] = self.goal.name
        return observation, reward, terminated, truncated, info

    def compute_reward(
        self, achieved_goal: np.ndarray, desired_goal: np.ndarray, info: Any = None
    ) -> np.ndarray:
        """The one-toy reward on the positions where the toys agree; a failure where not."""
        achieved, desired = np.asarray(achieved_goal), np.asarray(desired_goal)
        same = np.all(achieved[..., TOY_PART] == desired[..., TOY_PART], axis=-1)
        reward = super().compute_reward(achieved[..., POSITION_PART], desired[..., POSITION_PART])
        # Another toy is a failure: -1, or (dense) minus the distance of all five numbers.
        other = -1.0 if self.reward_type == SPARSE else -goals.distance(achieved, desired)
        return np.where(same, reward, other)

    def _drawn_goal(self, room: Any) -> tuple[np.ndarray, str | None]:
        self.goal = goals.GOALS[TOYS[int(self.np_random.integers(len(TOYS)))]]
        return super()._drawn_goal(room)

    def _given_goal(self, options: dict[str, Any] | None) -> np.ndarray | None:
        given = dict(options or {}).get(DESIRED_GOAL)
        if given is None or set(options or {}) != {DESIRED_GOAL}:
            return super()._given_goal(options)  # None, or the one-line refusal of an option
        try:
            goal = np.asarray(given, dtype=np.float64)
        except (TypeError, ValueError):
            raise ValueError(f"{DESIRED_GOAL} must be real numbers, got {given!r}") from None
        if goal.shape != (GOAL_DIM,):
            raise ValueError(f"{DESIRED_GOAL} must have shape ({GOAL_DIM},), got {goal.shape}")
        which = goal[TOY_PART]
        if sorted(which.tolist()) != [0.0] * (len(TOYS) - 1) + [1.0]:
            raise ValueError(
                f"{DESIRED_GOAL} must start with a toy's one-hot ({len(TOYS)} numbers, one 1), "
                f"got {which.tolist()}"
            )
        point = goal[POSITION_PART]
        bound = float(self.goal_space.high[-1])
        if not np.all(np.isfinite(point)) or np.any(np.abs(point.astype(SPACE_DTYPE)) > bound):
            raise ValueError(
                f"{DESIRED_GOAL}'s point must be finite and within +-{bound:g}, got "
                f"{point.tolist()}"
            )
        self.goal = goals.GOALS[TOYS[int(np.argmax(which))]]
        return point

    def _observation(self, observation: np.ndarray, achieved: np.ndarray) -> DictObs:
        one = super()._observation(observation, achieved)
        toy = np.zeros(len(TOYS), dtype=SPACE_DTYPE)
        toy[TOYS.index(self.goal.name)] = 1.0
        for key in ("achieved_goal", DESIRED_GOAL):
            one[key] = np.concatenate([toy, one[key]])
        return one


def make_toys_goal_registered(**kwargs: Any) -> PlayroomToysGoalEnv:
    """The environment of a registered toys id (sim/envs/versions.py), unwrapped, as
    `gymnasium.make` builds it."""
    return PlayroomToysGoalEnv(**kwargs)
