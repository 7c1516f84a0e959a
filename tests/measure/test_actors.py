"""The measures ask actors (experiments/measure/actors.py): the Model Babbling agent gets the
very tables it got before they did, and a goal-conditioned policy (policy_actor.py) is scored
on the same tests, goals and random reference, asked as its goal environment asks it."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest
from before_actors import ITERATIONS, PLACEMENTS, SEED, TABLES, evaluated_trial, recorded

from experiments.baseline.settings import BaselineSettings, trial_config
from experiments.measure.evaluation import (
    GOAL_TIMES,
    EvaluationSettings,
    competence_of,
    goal_trajectory,
)
from experiments.measure.policy_actor import PolicyActor, goal_end, observation_of
from experiments.measure.study_measure import StudyMeasureSettings, study_tests_of
from experiments.run.trial_parts import fresh_trial_parts
from models.layout import ARM_DIM
from sim.envs.goal_env import PlayroomGoalEnv
from sim.envs.gym_env import ARM_PART, VOICE_PART


class FixedPolicy:
    """A policy of stable-baselines3's form that always answers `action`, and keeps what it was
    asked."""

    def __init__(self, action: np.ndarray) -> None:
        self.action = np.asarray(action, dtype=np.float32)
        self.asked: list[dict] = []

    def predict(self, observation, deterministic=False):
        assert deterministic  # the measure asks without exploration
        self.asked.append(observation)
        return self.action.copy(), None


def resting_action() -> np.ndarray:
    """The arm (a[0] < 0) with the command of the arm at rest (zeros)."""
    action = np.zeros(1 + ARM_DIM + 28)
    action[0] = -1.0
    return action


def test_the_learner_gets_the_tables_recorded_before_the_measures_asked_actors(tmp_path):
    trial = evaluated_trial(tmp_path / "trial")
    for name in TABLES:
        pd.testing.assert_frame_equal(
            pd.read_parquet(trial / name), pd.read_parquet(recorded(name))
        )


def test_a_policy_is_tested_on_the_learners_placements_goals_and_random_reference():
    # The baseline of the recorded trial's world and seed, tested in that trial's room.
    settings = BaselineSettings(steps=ITERATIONS, seed=SEED, preset="project")
    _, room = fresh_trial_parts(trial_config(settings))
    policy = FixedPolicy(resting_action())
    actor = PolicyActor({1: policy, 2: policy, 3: policy})
    table = competence_of(actor, room, EvaluationSettings(n_placements=PLACEMENTS))
    learner = pd.read_parquet(recorded("competence.parquet"))
    same = ["ring", "placement", "toy", "x", "y", "distance", "random_error"]
    pd.testing.assert_frame_equal(table[same], learner[same])
    assert (table["random_goal_moved_by"] == learner["random_goal_moved_by"]).all()
    # A table of the same form; the policy has no memories to report distances to.
    assert list(table.columns) == list(learner.columns)
    assert table["arm_nn_distance"].isna().all() and not table["untrained"].any()
    # It was asked each test once, toy by toy, for the toy at the base.
    assert len(policy.asked) == len(table)
    for asked in policy.asked:
        np.testing.assert_array_equal(asked["desired_goal"], np.zeros(2, np.float32))


@pytest.mark.parametrize("grasp", ["kinematic", "physical"])
def test_a_policy_resting_the_arm_scores_the_at_rest_errors(grasp):
    settings = BaselineSettings(steps=30, grasp=grasp, seed=1)
    _, room = fresh_trial_parts(trial_config(settings))
    policy = FixedPolicy(resting_action())
    table = competence_of(
        PolicyActor({1: policy, 2: policy, 3: policy}), room, EvaluationSettings(3, seed=9)
    )
    assert set(table["strategy"]) == {"hand"} and set(table["stick_contact"]) == {"untouched"}
    # A toy at p that does not move, against the goal p (1 - t): error = |p| sqrt(sum t^2),
    # unless the resting hand (at (0, 0.5)) grabs it at once.
    far = np.hypot(table["x"], table["y"] - 0.5) > 0.15
    expected = table["distance"] * np.sqrt(np.sum(GOAL_TIMES**2))
    np.testing.assert_allclose(table["error"][far], expected[far], atol=1e-6)
    # The study's tests of the same policy: the same rule, where the scene carries over.
    tests = study_tests_of(
        PolicyActor({1: policy, 2: policy, 3: policy}), room, StudyMeasureSettings(2)
    )
    assert len(tests) == 3 * 2 * 3 and "vocal" not in set(tests["strategy"])
    # (The study's "tool" is any motion of the stick's x: on the physical backend a stick
    # settling on the table by a hair counts: experiments/measure/study_measure.py.)
    assert set(tests["stick_contact"]) <= {"untouched", "pushed"}


def test_the_policy_reads_the_voice_as_its_environment_does():
    action = np.linspace(-0.9, 0.9, 50)
    action[0] = 0.5  # a[0] >= 0: the voice
    actor = PolicyActor({t: FixedPolicy(action) for t in (1, 2, 3)})
    choice = actor.choose(2, np.zeros(10), goal_trajectory(np.array([0.3, 0.1])))
    assert choice.motor_space == "voice"
    np.testing.assert_array_equal(choice.command, action[VOICE_PART].astype(np.float32))
    action[0] = -0.5
    actor = PolicyActor({t: FixedPolicy(action) for t in (1, 2, 3)})
    choice = actor.choose(2, np.zeros(10), goal_trajectory(np.array([0.3, 0.1])))
    assert choice.motor_space == "arm"
    np.testing.assert_array_equal(choice.command, action[ARM_PART].astype(np.float32))
    with pytest.raises(ValueError, match="must lie in"):
        PolicyActor({t: FixedPolicy(action * 2) for t in (1, 2, 3)}).choose(
            1, np.zeros(10), np.zeros(10)
        )
    with pytest.raises(ValueError, match=r"none for \[3\]"):
        PolicyActor({1: FixedPolicy(action), 2: FixedPolicy(action)})


@pytest.mark.parametrize("toy", [1, 3])
def test_the_test_observation_is_the_goal_environments_first_one(toy):
    env = PlayroomGoalEnv(goal=f"toy{toy}")
    observation, _ = env.reset(seed=5, options={"desired_goal": np.zeros(2)})
    context = env.playroom.movement_env.room.context()
    goal = goal_trajectory(context[2 * toy : 2 * toy + 2])
    asked = observation_of(toy, context, goal)
    assert set(asked) == set(observation)
    for key, value in observation.items():
        assert asked[key].dtype == value.dtype
        np.testing.assert_array_equal(asked[key], value)
    np.testing.assert_array_equal(goal_end(goal), [0.0, 0.0])
