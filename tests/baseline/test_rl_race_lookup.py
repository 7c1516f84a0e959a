"""The race's lookup check (experiments/baseline/race_lookup.py): Model Babbling's memory asked
by where the toy starts and ends picks another stored experience than the race's straight
question where they disagree, and a directory without a finished race is refused in one line."""

from __future__ import annotations

import gymnasium
import numpy as np

import sim.envs  # noqa: F401  (registers the ids)
from experiments.baseline import race_learners as rl
from experiments.baseline.race_lookup import start_end_lookup_act
from experiments.cli.main import main
from learner.agent import Agent
from models.layout import ARM_DIM, CONTEXT_DIM, N_SAMPLES
from sim.envs.gym_env import ARM_PART
from sim.envs.toys_goal_env import POSITION_PART, TOY_PART


def _way(points: list[np.ndarray]) -> np.ndarray:
    xy = np.array(points)
    return np.concatenate([xy[:, 0], xy[:, 1]])


def test_the_lookup_asks_by_start_and_end_where_the_race_asks_by_the_whole_way():
    env = gymnasium.make(rl.toys_goal_id("kinematic"), motor="both")
    observation, _ = env.reset(seed=1_000_000)
    lies, desired = observation["achieved_goal"][POSITION_PART], observation["desired_goal"]
    toy = int(np.argmax(desired[TOY_PART])) + 1
    point = desired[POSITION_PART]
    agent = Agent(rng=0)
    model = agent.models[agent.toy_models(toy)[0]]
    context = np.asarray(observation["observation"][:CONTEXT_DIM], dtype=np.float64)
    # A: the straight way, to a point beside the goal's (close in the whole way, wrong at the
    # end); B: still, then taken to the very point at the end (how a hand moves a toy).
    beside = point + (point - lies) / np.linalg.norm(point - lies) * 0.15
    straight_beside = rl.trajectory_toward(lies, beside)
    still_then_there = _way([lies] * (N_SAMPLES - 1) + [point])
    commands = np.array([np.full(ARM_DIM, 0.25), np.full(ARM_DIM, -0.25)])
    model.extend(commands, np.tile(context[model.context_dims], (2, 1)),
                 np.array([straight_beside, still_then_there]))  # fmt: skip
    race_question = rl.model_babbling_act(agent)(observation)
    lookup = start_end_lookup_act(agent)(observation)
    np.testing.assert_array_equal(race_question[ARM_PART], commands[0].astype(np.float32))
    np.testing.assert_array_equal(lookup[ARM_PART], commands[1].astype(np.float32))


def test_a_directory_without_a_race_is_refused_in_one_line(tmp_path, capsys):
    assert main(["rl-race-lookup", str(tmp_path)]) == 2
    err = capsys.readouterr().err
    assert "holds no race" in err and "Traceback" not in err
