"""The goal-conditioned environments (sim/envs/goal_env.py) as a user of hindsight relabelling
relies on them: Gymnasium's checker on every id, `compute_reward` on a batch agreeing with the
rewards of the steps, a goal reached reported as a success, goals drawn where the docstring says,
and refused input in one line."""

from __future__ import annotations

import re
import warnings

import gymnasium
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env
from scripted import Waypoint, arm_command_through

from models.layout import block_slice
from sim.envs import GOAL_VARIANTS, PlayroomGoalEnv
from sim.envs import goals as g
from sim.envs.versions import GOAL_MOVEMENTS, GOAL_VERSION

IDS = list(GOAL_VARIANTS)
ARM, VOICE = -1.0, 1.0  # a[0]: the motor space of motor="both"
MOVEMENTS = 3  # episodes of a few movements, where a test needs them
# Toys parked in ring 3, away from the scripted reach for the stick.
PARKED_TOYS = np.array([[-0.75, -0.55], [-0.15, -0.9], [-0.8, 0.5]])


def _action(space: float, rng: np.random.Generator) -> np.ndarray:
    action = rng.uniform(-1, 1, 50).astype(np.float32)
    action[0] = space
    return action


@pytest.fixture
def headless(monkeypatch):
    monkeypatch.delenv("DISPLAY", raising=False)
    monkeypatch.delenv("WAYLAND_DISPLAY", raising=False)


# The ecosystem's checker --------------------------------------------------------------------
@pytest.mark.parametrize("env_id", IDS)
def test_gymnasiums_whole_checker_passes_on_every_goal_id(env_id, headless):
    env = gymnasium.make(f"sim.envs:{env_id}")
    assert type(env) is PlayroomGoalEnv  # no wrapper: the environment itself
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # the checker's advice fails too
        check_env(env)
    room = env.playroom.movement_env.room
    assert room.grasp == GOAL_VARIANTS[env_id].get("grasp", "kinematic")
    assert env.spec.max_episode_steps is None  # the environment ends its own episodes
    assert env.observation_space["achieved_goal"].dtype == np.float32


# Rewards as hindsight relabelling computes them ---------------------------------------------
@pytest.mark.parametrize("env_id", IDS)
@pytest.mark.parametrize("kind", ["sparse", "dense"])
def test_compute_reward_on_a_batch_equals_the_rewards_of_the_steps(env_id, kind):
    env = gymnasium.make(env_id, motor="both", movements=MOVEMENTS, reward=kind)
    rng = np.random.default_rng(1)
    achieved, desired, rewards, infos = [], [], [], []
    for seed in range(3):
        obs, _ = env.reset(seed=seed)
        for k in range(MOVEMENTS):
            obs, reward, terminated, truncated, info = env.step(_action((ARM, VOICE)[k % 2], rng))
            assert terminated == (k == MOVEMENTS - 1) and not truncated
            distance = g.distance(obs["achieved_goal"], obs["desired_goal"])
            assert info["is_success"] == float(distance < env.unwrapped.tolerance)
            achieved.append(obs["achieved_goal"])
            desired.append(obs["desired_goal"])
            rewards.append(reward)
            infos.append(info)
    a, d = np.stack(achieved), np.stack(desired)
    batch = env.unwrapped.compute_reward(a, d, np.array(infos))
    assert batch.shape == (len(rewards),)
    np.testing.assert_array_equal(batch, rewards)
    # Relabelled as HER does (desired := an achieved goal of the episode): successes appear.
    assert (env.unwrapped.compute_reward(a, a, infos) == 0.0).all()
    if kind == "sparse":
        relabelled = env.unwrapped.compute_reward(a, a[::-1].copy(), infos)
        assert set(np.unique(relabelled)) <= {-1.0, 0.0}
    else:  # minus the distance
        np.testing.assert_allclose(batch, -np.linalg.norm(a - d, axis=1), rtol=1e-6)
    assert not env.unwrapped.compute_terminated(a, d, infos).any()


@pytest.mark.parametrize(("goal", "tol"), [("hand", 0.1), ("toy2", 0.1), ("word", 0.4)])
def test_the_tolerance_is_the_studys_distance_and_strict(goal, tol):
    env = PlayroomGoalEnv(goal)
    assert env.tolerance == tol
    dim = env.goal.dim
    desired = np.zeros((4, dim))
    achieved = np.zeros((4, dim))
    achieved[:, 0] = [0.0, tol * 0.999, tol, tol * 1.001]
    np.testing.assert_array_equal(env.compute_reward(achieved, desired, None), [0, 0, -1, -1])
    assert env.compute_reward(achieved[1], desired[1], {}) == 0.0


# A goal reached -----------------------------------------------------------------------------
@pytest.mark.parametrize("grasp", ["kinematic", "physical"])
@pytest.mark.parametrize("goal", ["hand", "toy3", "word"])
def test_a_desired_goal_set_to_what_a_command_achieves_is_a_success(grasp, goal):
    env = PlayroomGoalEnv(goal, grasp=grasp)  # each goal's own motor space
    action = np.random.default_rng(3).uniform(-1, 1, env.action_space.shape).astype(np.float32)
    env.reset(seed=5)
    achieved = env.step(action)[0]["achieved_goal"]
    # The same room, the same command: the same outcome, now the goal.
    obs, _ = env.reset(seed=5, options={"desired_goal": achieved})
    np.testing.assert_array_equal(obs["desired_goal"], achieved)
    obs, reward, _, _, info = env.step(action)
    assert (reward, info["is_success"]) == (0.0, 1.0)
    # Elsewhere it is not reached.
    env.reset(seed=5, options={"desired_goal": achieved + 0.5})
    assert env.step(action)[1] == -1.0


def _stick_sweep(env: PlayroomGoalEnv) -> tuple[np.ndarray, np.ndarray]:
    """An arm action that takes the stick's handle and carries it to a point, and that point."""
    room = env.playroom.movement_env.room
    room.arrange(toys=PARKED_TOYS)
    hx, hy = room.context()[:2]
    end = np.array([hx + 0.3, hy + 0.3])
    waypoints = [
        Waypoint(12, (hx - 0.15, hy + 0.2)),
        Waypoint(24, (hx - 0.04, hy + 0.02), np.pi / 2),
        Waypoint(50, tuple(end)),
    ]
    m, error = arm_command_through(waypoints, room.config)
    assert error < 0.02
    return m.astype(np.float32), end


def test_the_stick_carried_to_the_desired_point_reaches_the_goal():
    env = gymnasium.make(f"sim.envs:PlayroomStickGoal-v{GOAL_VERSION}", movements=MOVEMENTS)
    obs, _ = env.reset(seed=0, options={"desired_goal": [0.05, 0.3]})
    np.testing.assert_allclose(obs["achieved_goal"], [-0.25, 0.0])  # the stick's start
    action, end = _stick_sweep(env.unwrapped)
    np.testing.assert_allclose(end, [0.05, 0.3])
    obs, reward, _, _, info = env.step(action)
    assert (reward, info["is_success"]) == (0.0, 1.0)
    handle = obs["observation"][10:][block_slice("stick")].reshape(2, 5)[:, -1]
    np.testing.assert_array_equal(obs["achieved_goal"], handle)  # the study's stick model
    # A still arm leaves the stick where it was dropped: still reached, and the episode ends
    # (terminated) after its movements.
    still = np.zeros(21, dtype=np.float32)
    assert env.step(still)[1:4] == (0.0, False, False)
    assert env.step(still)[1:4] == (0.0, True, False)


def test_the_word_goal_is_the_agents_own_sound_never_the_caregivers_word():
    env = PlayroomGoalEnv("word", motor="both", movements=2)
    obs, info = env.reset(seed=2)
    room = env.playroom.movement_env.room
    assert info["desired_word"] in room.vocal_tract.config.words
    np.testing.assert_allclose(
        obs["desired_goal"], room.vocal_tract.word_features(info["desired_word"]), atol=1e-6
    )
    # After an arm movement the sound block holds her word; the agent said nothing.
    obs, reward, *_ = env.step(_action(ARM, np.random.default_rng(0)))
    assert np.abs(obs["observation"][10:][block_slice("sound")]).max() > 0.1
    np.testing.assert_array_equal(obs["achieved_goal"], np.zeros(10))
    assert reward == -1.0  # silence is far from every word
    obs, *_ = env.step(_action(VOICE, np.random.default_rng(0)))
    np.testing.assert_array_equal(
        obs["achieved_goal"], obs["observation"][10:][block_slice("sound")]
    )


# Where goals are drawn ----------------------------------------------------------------------
@pytest.mark.parametrize(("goal", "low", "high"), [("hand", 0.0, 0.5), ("toy1", 0.0, 0.75)])
def test_desired_points_follow_the_studys_placement_rule_within_reach(goal, low, high):
    env = PlayroomGoalEnv(goal)
    room = env.playroom.movement_env.room
    rng = np.random.default_rng(0)
    points = np.array([g.draw_desired(env.goal, room, rng)[0] for _ in range(4000)])
    radii = np.linalg.norm(points, axis=1)
    assert radii.min() >= low and radii.max() <= high and radii.max() > 0.97 * high
    if goal == "toy1":  # rings 1 and 2 with equal chance, ring 3 never
        assert abs(np.mean(radii < 0.5) - 0.5) < 0.03
    else:  # a radius uniform in the ring, as the study places toys (not area-uniform)
        assert abs(np.median(radii) - 0.25) < 0.02


def test_the_docstring_tells_the_ids_goals_and_episode_length():
    doc = PlayroomGoalEnv.__doc__ or ""
    for section in ("Description", "Action Space", "Observation Space", "Rewards",
                    "Starting State", "Episode End", "Arguments", "Version History"):  # fmt: skip
        assert f"## {section}" in doc
    assert all(env_id in doc for env_id in IDS)
    assert all(f'"{name}"' in doc for name in g.GOALS)
    assert re.search(r"Terminated after `movements` movements \(1 by default", doc)
    assert GOAL_MOVEMENTS == 1 and "* v1:" in doc and "* v0:" in doc


# Refused input ------------------------------------------------------------------------------
@pytest.mark.parametrize(
    ("make", "message"),
    [
        (lambda: PlayroomGoalEnv("tail"), "^unknown goal 'tail': one of hand, stick, toy1"),
        (lambda: gymnasium.make(IDS[0], iterations=5), "give movements=5, not iterations$"),
        (lambda: PlayroomGoalEnv(motor="legs"), "^unknown motor 'legs': one of arm, voice, both"),
        (lambda: PlayroomGoalEnv(movements=0), "^movements must be a positive integer, got 0$"),
        (lambda: PlayroomGoalEnv(movements=1.5), "^movements must be a positive integer"),
        (lambda: PlayroomGoalEnv(reward="shaped"), "^unknown reward 'shaped': one of sparse, den"),
        (lambda: PlayroomGoalEnv().step(np.zeros(21)), "^call reset\\(\\) first$"),
        (lambda: _reset(PlayroomGoalEnv()).step(np.zeros(50)), "must have shape \\(21,\\), got"),
        (lambda: PlayroomGoalEnv().reset(options={"goal": 1}), "only the option 'desired_goal'"),
        (lambda: PlayroomGoalEnv().reset(options={"desired_goal": [1.0]}), "shape \\(2,\\)"),
        (lambda: PlayroomGoalEnv().reset(options={"desired_goal": [np.nan, 0]}), "within \\+-1.3"),
        (lambda: PlayroomGoalEnv().compute_reward(np.zeros(2), np.zeros(3), {}), "last axis"),
    ],
)
def test_bad_input_is_refused_in_one_line(make, message):
    with pytest.raises((ValueError, RuntimeError), match=message) as caught:
        make()
    assert "\n" not in str(caught.value)


def _reset(env: PlayroomGoalEnv) -> PlayroomGoalEnv:
    env.reset(seed=0)
    return env
