"""One goal environment for the three toys (sim/envs/toys_goal_env.py), as one goal-conditioned
policy of the three relies on it: the ecosystems' checkers take what `gymnasium.make` gives, the
toy is drawn each episode and named in the goal, goals are never met at reset, the ring is in
`info`, and `compute_reward` agrees with the steps and fails another toy's goal."""

from __future__ import annotations

import warnings

import gymnasium
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env
from rl_extra import require

from sim.envs import TOYS_GOAL_VARIANTS
from sim.envs import goals as g
from sim.envs.toys_goal_env import POSITION_PART, PlayroomToysGoalEnv

IDS = list(TOYS_GOAL_VARIANTS)
RESETS = 150  # resets counted for the toys drawn and the goals met at rest


@pytest.mark.parametrize("env_id", IDS)
def test_gymnasiums_whole_checker_passes_on_each_toys_id(env_id):
    env = gymnasium.make(f"sim.envs:{env_id}")
    assert type(env) is PlayroomToysGoalEnv  # no wrapper: the environment itself
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        check_env(env)
    assert env.playroom.movement_env.room.grasp == TOYS_GOAL_VARIANTS[env_id].get(
        "grasp", "kinematic"
    )
    assert env.action_space.shape == (21,)  # the arm alone
    assert env.observation_space["desired_goal"].shape == (5,)


@pytest.mark.slow
@pytest.mark.parametrize("env_id", IDS)
def test_stable_baselines_check_env_takes_what_make_gives_whole(env_id):
    require("stable_baselines3")
    from stable_baselines3.common.env_checker import check_env as sb3_check_env

    sb3_check_env(gymnasium.make(f"sim.envs:{env_id}"))


def test_each_toy_is_drawn_named_in_the_goal_and_never_met_at_reset():
    env = gymnasium.make(IDS[0])
    toys, rings = [], []
    for seed in range(RESETS):
        obs, info = env.reset(seed=seed)
        which = obs["desired_goal"][:3]
        assert sorted(which.tolist()) == [0.0, 0.0, 1.0]
        np.testing.assert_array_equal(obs["achieved_goal"][:3], which)
        assert info["toy"] == f"toy{int(np.argmax(which)) + 1}"
        point = obs["desired_goal"][POSITION_PART]
        # Not met at rest: the toy lies at the tolerance or more from its goal.
        assert g.distance(obs["achieved_goal"][POSITION_PART], point) >= env.tolerance
        assert info["ring"] == ("near" if np.linalg.norm(point) <= 0.5 else "far")
        toys.append(info["toy"])
        rings.append(info["ring"])
    for toy in ("toy1", "toy2", "toy3"):
        assert RESETS / 6 < toys.count(toy) < RESETS / 2  # equal chance, 1/3 each
    assert RESETS / 4 < rings.count("far") < 3 * RESETS / 4


@pytest.mark.parametrize("kind", ["sparse", "dense"])
def test_compute_reward_agrees_with_the_steps_and_fails_another_toys_goal(kind):
    env = gymnasium.make(IDS[0], reward=kind)
    rng = np.random.default_rng(0)
    achieved, desired, rewards = [], [], []
    for seed in range(6):
        env.reset(seed=seed)
        obs, reward, terminated, _, info = env.step(rng.uniform(-1, 1, 21).astype(np.float32))
        assert terminated and info["toy"] in ("toy1", "toy2", "toy3") and "ring" in info
        achieved.append(obs["achieved_goal"])
        desired.append(obs["desired_goal"])
        rewards.append(reward)
    np.testing.assert_array_equal(
        env.compute_reward(np.array(achieved), np.array(desired)), rewards
    )
    # The achieved goal itself is a success; the same point of another toy is not.
    same = env.compute_reward(achieved[0], achieved[0])
    other = achieved[0].copy()
    other[:3] = np.roll(other[:3], 1)
    failed = env.compute_reward(achieved[0], other)
    assert same == 0.0 and (failed == -1.0 if kind == "sparse" else failed < 0.0)


def test_a_given_goal_sets_the_toy_and_a_step_that_brings_it_there_succeeds():
    env = gymnasium.make(IDS[0])
    env.reset(seed=0)
    command = np.random.default_rng(2).uniform(-1, 1, 21).astype(np.float32)
    outcome = env.step(command)[0]["achieved_goal"]
    obs, info = env.reset(seed=0, options={"desired_goal": outcome})
    assert info["toy"] == env.unwrapped.goal.name
    np.testing.assert_array_equal(obs["desired_goal"], outcome)
    assert env.step(command)[4]["is_success"] == 1.0  # the same room, the same command


@pytest.mark.parametrize(
    ("options", "message"),
    [
        ({"desired_goal": [1, 0, 0, 0.1]}, "shape"),
        ({"desired_goal": [1, 1, 0, 0.1, 0.1]}, "one-hot"),
        ({"desired_goal": [0, 1, 0, 9.0, 0.1]}, "within"),
        ({"desired_goal": [0, 1, 0, 0.1, 0.1], "toy": 1}, "only the option"),
    ],
)
def test_bad_given_goals_are_refused_in_one_line(options, message):
    env = gymnasium.make(IDS[0])
    with pytest.raises(ValueError, match=message) as caught:
        env.reset(seed=0, options=options)
    assert "\n" not in str(caught.value)
    with pytest.raises(ValueError, match="draws its toy"):
        PlayroomToysGoalEnv(goal="toy1")


@pytest.mark.slow
def test_hindsight_relabelling_rewards_the_episodes_own_toy_at_its_own_outcome():
    require("stable_baselines3")
    from stable_baselines3 import SAC, HerReplayBuffer

    model = SAC("MultiInputPolicy", IDS[0], replay_buffer_class=HerReplayBuffer, seed=0)
    model.learn(300)  # SAC's default learning_starts is 100: 200 gradient steps, relabelled
    batch = model.replay_buffer.sample(256)
    # HER's "future" goal of a one-movement episode is its own outcome, of the same toy: a
    # success (0) among the failures (-1) of the drawn goals.
    assert set(np.unique(batch.rewards.numpy())) == {-1.0, 0.0}
    toys = batch.observations["desired_goal"][:, :3].numpy()
    np.testing.assert_array_equal(toys.sum(axis=1), 1.0)
