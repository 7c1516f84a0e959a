"""The race's learners on its held-out goals (race_settings.py): each asked, for the goal that
PlayroomToysGoal-v1 sets at `reset(seed=s)`, for one movement, scored by the environment
(`is_success`), with the goal's toy and ring. The deep RL learners act as the environment asks
(the arm's 21 numbers); Model Babbling through the measure's actor (experiments/measure/
actors.py `LearnerActor`: the toy's arm or voice model, whichever has the nearer experience,
inverted without exploration noise), in the same environment with both motor spaces
(`motor="both"`), whose goals are the same: the toy and its point are drawn alike whatever the
motor space. Model Babbling's models are of trajectories: its goal is the toy's straight way
from where it lies to the desired point, sampled at the measure's times
(experiments/measure/evaluation.py `GOAL_TIMES`), of which the environment scores the end."""

from __future__ import annotations

from collections.abc import Callable, Sequence

import gymnasium
import numpy as np
import pandas as pd

from experiments.measure.actors import LearnerActor
from experiments.measure.evaluation import GOAL_TIMES
from learner.agent import Agent
from models.layout import CONTEXT_DIM
from sim.envs.gym_env import ACTION_DIM, ARM_PART, SELECTOR, SPACE_DTYPE, VOICE_PART
from sim.envs.motor_spaces import SWITCH
from sim.envs.toys_goal_env import POSITION_PART, TOY_PART
from sim.envs.versions import TOYS_GOAL_VARIANTS

DictObs = dict[str, np.ndarray]
Act = Callable[[DictObs], np.ndarray]
TESTED = ["goal_seed", "toy", "ring", "motor_space", "reached"]


def toys_goal_id(grasp: str) -> str:
    """The registered id of the toys' goal environment for a grasp backend."""
    (found,) = [i for i, kw in TOYS_GOAL_VARIANTS.items() if kw.get("grasp", "kinematic") == grasp]
    return found


def tested_goals(
    act: Act, env: gymnasium.Env, seeds: Sequence[int], tries: int = 1
) -> pd.DataFrame:
    """`act`'s one movement toward the goal of `env.reset(seed=s)` for each seed (`tries`
    movements from the same start, each scored, for a noisy actor): a row per movement
    (TESTED: the goal's reset seed, toy, ring, the motor space played, whether it reached it)."""
    rows = []
    for seed in (s for s in seeds for _ in range(tries)):
        observation, info = env.reset(seed=seed)
        _, _, _, _, after = env.step(act(observation))
        rows.append(
            {
                "goal_seed": seed,
                "toy": info["toy"],
                "ring": info["ring"],
                "motor_space": after["motor_space"],
                "reached": bool(after["is_success"]),
            }
        )
    return pd.DataFrame(rows, columns=TESTED)


def trajectory_toward(start: np.ndarray, end: np.ndarray) -> np.ndarray:
    """(10,) the measure's goal form (5 x, then 5 y) of a toy moved straight from `start` to
    `end` (2,), sampled at GOAL_TIMES."""
    points = np.asarray(start) + np.outer(GOAL_TIMES, np.asarray(end) - np.asarray(start))
    return np.concatenate([points[:, 0], points[:, 1]])


def model_babbling_act(agent: Agent) -> Act:
    """Model Babbling's action in the toys' environment with both motor spaces (50 numbers:
    the switch, then the arm's and the voice's), chosen by the measure's actor."""
    actor = LearnerActor(agent)

    def act(observation: DictObs) -> np.ndarray:
        desired, lies = observation["desired_goal"], observation["achieved_goal"]
        toy = int(np.argmax(desired[TOY_PART])) + 1
        context = np.asarray(observation["observation"][:CONTEXT_DIM], dtype=np.float64)
        goal = trajectory_toward(lies[POSITION_PART], desired[POSITION_PART])
        choice = actor.choose(toy, context, goal)
        action = np.zeros(ACTION_DIM, dtype=SPACE_DTYPE)
        action[SELECTOR] = SWITCH[choice.motor_space]
        action[ARM_PART if choice.motor_space == "arm" else VOICE_PART] = choice.command
        return action

    return act
