"""The environments of sim/envs/: dm_env's and Gymnasium's checkers, episodes, seeds, what a
command does to the observation, and refused actions."""

from __future__ import annotations

import unittest
import warnings

import dm_env
import gymnasium
import numpy as np
import pytest
from dm_env import test_utils
from gymnasium.utils.env_checker import check_env
from scripted import Waypoint, arm_command_through

from models.layout import ARM_DIM, VOICE_DIM, block_slice
from sim import Playroom
from sim import events as ev
from sim.config import world_preset
from sim.envs import GYM_ID, PlayroomGymEnv, PlayroomMovementEnv
from sim.envs.world import EVENT_KINDS

# Short episodes: the checkers then see their ends.
ITERATIONS = 3
# Toys parked in ring 3, away from the scripted reach for the stick.
PARKED_TOYS = np.array([[-0.75, -0.55], [-0.15, -0.9], [-0.8, 0.5]])


def _random_actions(n: int, seed: int = 0) -> list[dict]:
    rng = np.random.default_rng(seed)
    return [
        {
            "motor_space": k % 2,
            "arm": rng.uniform(-1, 1, ARM_DIM),
            "voice": rng.uniform(-1, 1, VOICE_DIM),
        }
        for k in range(n)
    ]


# The ecosystems' checkers -------------------------------------------------------------------
class TestMovementEnvIsADmEnv(test_utils.EnvironmentTestMixin, unittest.TestCase):
    """dm_env's own contract checks (FIRST, MID, LAST, specs), run by pytest."""

    def make_object_under_test(self):
        return PlayroomMovementEnv(iterations=ITERATIONS, seed=0)

    def make_action_sequence(self):
        # Arm and voice in turn, past the end of an episode, so that LAST -> FIRST is checked.
        yield from _random_actions(2 * ITERATIONS + 2)

    def test_longer_action_sequence_reaches_last(self):
        self.reset_environment()
        kinds = [self.step_environment(a).step_type for a in self.make_action_sequence()]
        assert kinds[ITERATIONS - 1] is dm_env.StepType.LAST
        assert kinds[ITERATIONS] is dm_env.StepType.FIRST


@pytest.fixture
def headless(monkeypatch):
    """A machine without a display, as a cluster node or a CI runner."""
    monkeypatch.delenv("DISPLAY", raising=False)
    monkeypatch.delenv("WAYLAND_DISPLAY", raising=False)


def _checked_quietly(env: gymnasium.Env) -> None:
    # Gymnasium's checker, unmodified: it warns about what it only recommends, and here every
    # warning fails. Its render check makes and renders the environment in each declared mode
    # ("rgb_array" and "rgb_array_list" offscreen here; "human" where a display exists:
    # tests/sim/envs/test_env_rendering.py runs it under Xvfb).
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        check_env(env)


def test_gym_env_passes_gymnasiums_whole_checker_through_make_without_a_display(headless):
    env = gymnasium.make(GYM_ID)
    _checked_quietly(env.unwrapped)
    assert env.unwrapped.spec.id == GYM_ID
    # "human" is declared only where it can open a window; asked for, it says why not.
    assert env.unwrapped.metadata["render_modes"] == ["rgb_array", "rgb_array_list"]


def test_the_viewer_is_declared_where_a_display_exists(monkeypatch):
    monkeypatch.setenv("DISPLAY", ":99")  # (no window opens without a render mode)
    modes = PlayroomGymEnv(iterations=2).metadata["render_modes"]
    assert modes == ["human", "rgb_array", "rgb_array_list"]


def test_gym_env_is_found_by_module_path_and_builds_a_physical_room_that_passes_the_checker(
    headless,
):
    env = gymnasium.make(f"sim.envs:{GYM_ID}", grasp="physical", preset="project")
    assert env.unwrapped.movement_env.room.grasp == "physical"
    _checked_quietly(env.unwrapped)


# Episodes and seeds -------------------------------------------------------------------------
def test_dm_episode_ends_with_a_truncation_after_its_iterations_then_starts_again():
    env = PlayroomMovementEnv(iterations=ITERATIONS, seed=4)
    steps = [env.reset()] + [env.step(a) for a in _random_actions(ITERATIONS + 1)]
    assert [s.step_type for s in steps] == (
        [dm_env.StepType.FIRST]
        + [dm_env.StepType.MID] * (ITERATIONS - 1)
        + [dm_env.StepType.LAST, dm_env.StepType.FIRST]
    )
    assert all(s.reward == 0.0 and s.discount == 1.0 for s in steps[1 : ITERATIONS + 1])
    # The next episode is a new room of a drawn seed, at its first iteration.
    assert env.room.iteration == 0 and env.episode_seed != 4
    np.testing.assert_array_equal(steps[-1].observation["feedback"], np.zeros(60))


def test_gym_episode_is_truncated_never_terminated_and_then_wants_a_reset():
    env = PlayroomGymEnv(iterations=ITERATIONS)
    with pytest.raises(RuntimeError, match="call reset"):
        env.step(np.zeros(50))
    env.reset(seed=1)
    ends = [env.step(env.action_space.sample())[2:4] for _ in range(ITERATIONS)]
    assert ends == [(False, False)] * (ITERATIONS - 1) + [(False, True)]
    with pytest.raises(RuntimeError, match=f"ended after {ITERATIONS} iterations"):
        env.step(np.zeros(50))


def _episode(env: PlayroomMovementEnv, seed: int | None, n: int = 4) -> np.ndarray:
    first = env.reset() if seed is None else env.reset(seed=seed)
    steps = [first] + [env.step(a) for a in _random_actions(n, seed=9)]
    return np.array([np.r_[s.observation["context"], s.observation["feedback"]] for s in steps])


def test_reset_with_a_seed_replays_the_room_of_that_seed():
    env = PlayroomMovementEnv(iterations=10)
    a, b, c = _episode(env, 5), _episode(env, 6), _episode(env, 5)
    np.testing.assert_array_equal(a, c)
    assert not np.array_equal(a[0], b[0])
    # The room of seed 5 is a trial's: Playroom(seed=5) given the same commands.
    room = Playroom(seed=5)
    np.testing.assert_array_equal(a[0, :10], room.context())
    for k, action in enumerate(_random_actions(4, seed=9), start=1):
        space = ("arm", "voice")[action["motor_space"]]
        feedback = room.act(space, action[space])
        np.testing.assert_array_equal(a[k], np.r_[room.context(), feedback.s])


def test_unseeded_resets_follow_the_last_seed_in_dm_env_and_gymnasium_alike():
    dm = PlayroomMovementEnv(iterations=10)
    gym = PlayroomGymEnv(iterations=10)
    _episode(dm, 8, n=0)
    gym.reset(seed=8)
    for _ in range(2):
        dm_obs = dm.reset().observation
        gym_obs, info = gym.reset()
        assert info["seed"] == dm.episode_seed != 8
        expected = np.r_[dm_obs["context"], dm_obs["feedback"]].astype(np.float32)
        np.testing.assert_array_equal(gym_obs, expected)


# What a command does ------------------------------------------------------------------------
def _reach_for_the_stick(room: Playroom) -> np.ndarray:
    """An arm command that takes the stick's handle and sweeps it to the right."""
    hx, hy = room.context()[:2]
    waypoints = [
        Waypoint(12, (hx - 0.15, hy + 0.2)),
        Waypoint(24, (hx - 0.04, hy + 0.02), np.pi / 2),
        Waypoint(50, (hx + 0.3, hy + 0.3)),
    ]
    m, error = arm_command_through(waypoints, room.config)
    assert error < 0.02
    return m


def test_an_arm_command_reaching_the_stick_moves_it_in_the_observation():
    env = PlayroomMovementEnv(preset="project", iterations=10)
    env.reset(seed=0)
    env.room.arrange(toys=PARKED_TOYS)
    start = env.room.context()[:2].copy()
    m = _reach_for_the_stick(env.room)
    step = env.step({"motor_space": "arm", "arm": m})
    counts = dict(zip(EVENT_KINDS, step.observation["events"], strict=True))
    assert counts[ev.STICK_GRASPED] == 1 and counts[ev.STICK_MOVED] == 1
    assert [e.kind for e in env.last_feedback.events][:2] == [ev.STICK_GRASPED, ev.STICK_MOVED]
    # The stick block's last sample is where the stick lies in the next context.
    stick = step.observation["feedback"][block_slice("stick")].reshape(2, 5)[:, -1]
    np.testing.assert_allclose(step.observation["context"][:2], stick, atol=1e-9)
    assert np.linalg.norm(stick - start) > 0.1
    # The Gymnasium form sees the same: a[0] < 0 chooses the arm.
    gym = PlayroomGymEnv(preset="project", iterations=10)
    gym.reset(seed=0)
    gym.movement_env.room.arrange(toys=PARKED_TOYS)
    action = np.zeros(50)
    action[0], action[1:22] = -1.0, m
    obs, _, _, _, info = gym.step(action)
    np.testing.assert_array_equal(obs[:10], step.observation["context"].astype(np.float32))
    assert info["motor_space"] == "arm" and info["events"][0]["kind"] == ev.STICK_GRASPED


# Refused input ------------------------------------------------------------------------------
@pytest.mark.parametrize(
    ("action", "message"),
    [
        (np.zeros(21), "must be a dict"),
        ({"motor_space": 0, "arm": np.zeros(21), "leg": 1}, "unknown action keys"),
        ({"arm": np.zeros(21)}, "no 'motor_space'"),
        ({"motor_space": 2, "arm": np.zeros(21)}, "0 \\(arm\\), 1 \\(voice\\)"),
        ({"motor_space": "leg"}, "unknown motor space 'leg'"),
        ({"motor_space": 1, "arm": np.zeros(21)}, "holds no 'voice' command"),
        ({"motor_space": 0, "arm": np.zeros(28)}, "shape \\(21,\\)"),
        ({"motor_space": 0, "arm": np.full(21, 1.5)}, "in \\[-1, 1\\]"),
    ],
)
def test_dm_env_refuses_bad_actions_in_one_line_and_nothing_moves(action, message):
    env = PlayroomMovementEnv(iterations=10)
    env.reset(seed=0)
    before = env.room.get_state()
    with pytest.raises(ValueError, match=message):
        env.step(action)
    assert env.room.iteration == 0
    np.testing.assert_array_equal(env.room.get_state()["physics"], before["physics"])


@pytest.mark.parametrize(
    ("action", "message"),
    [
        (np.zeros(49), "shape \\(50,\\)"),
        (np.r_[np.nan, np.zeros(49)], "NaN or inf at indices \\[0 \\(nan\\)\\]$"),
        (
            np.r_[np.zeros(49), 2.0],
            "must lie in \\[-1, 1\\], outside at indices \\[49 \\(2.0\\)\\]",
        ),
        ("left", "50 real numbers in \\[-1, 1\\], got str"),
    ],
)
def test_gym_env_refuses_actions_outside_its_space(action, message):
    env = PlayroomGymEnv(iterations=10)
    env.reset(seed=0)
    with pytest.raises(ValueError, match=message):
        env.step(action)
    assert env.movement_env.room.iteration == 0


def _as_dm_action(flat: np.ndarray) -> dict:
    """The dm_env action of a flat Gymnasium one, both commands given."""
    arm = flat.dtype.kind == "f" and flat[0] < 0
    return {"motor_space": 0 if arm else 1, "arm": flat[1:22], "voice": flat[22:50]}


# Both forms share one check (sim/envs/actions.py): the same values refused with the same words.
@pytest.mark.parametrize(
    ("flat", "message"),
    [
        # NumPy would drop the imaginary part with a ComplexWarning, or read True as 1.0.
        (np.zeros(50, dtype=complex), "real numbers in \\[-1, 1\\], got an array of complex128"),
        (np.zeros(50, dtype=bool), "real numbers in \\[-1, 1\\], got an array of bool"),
        (np.array([0.0] * 49 + [None]), "real numbers in \\[-1, 1\\], got an array of object"),
        (np.array(["0"] * 50), "real numbers in \\[-1, 1\\], got an array of <U1"),
        # The arm is chosen: a NaN in the voice's command is refused all the same.
        (
            np.r_[-1.0, np.zeros(21), np.nan, np.zeros(27)],
            "NaN or inf at indices \\[\\d+ \\(nan\\)\\]$",
        ),
        # The exact value, not a rounding of it that reads as inside the range.
        (np.r_[-1.0, -1.0000001, np.zeros(48)], "outside at indices \\[\\d+ \\(-1.0000001\\)\\]$"),
        # A few indices, then how many more.
        (
            np.r_[-1.0, np.full(49, np.inf)],
            "\\[(\\d+ \\(inf\\), ){4}\\d+ \\(inf\\)\\] and \\d+ more$",
        ),
    ],
)
def test_both_environments_refuse_the_same_actions_in_the_same_words(flat, message):
    gym = PlayroomGymEnv(iterations=10)
    gym.reset(seed=0)
    dm = PlayroomMovementEnv(iterations=10)
    dm.reset(seed=0)
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # a ComplexWarning is no refusal
        with pytest.raises(ValueError, match=message):
            gym.step(flat)
        with pytest.raises(ValueError, match=message):
            dm.step(_as_dm_action(flat))
    assert gym.movement_env.room.iteration == dm.room.iteration == 0


def test_the_index_lists_of_the_two_forms_count_within_their_own_arrays():
    action = np.r_[1.0, np.zeros(21), np.full(28, np.nan)]
    gym = PlayroomGymEnv(iterations=10)
    gym.reset(seed=0)
    with pytest.raises(ValueError) as caught:
        gym.step(action)
    assert str(caught.value) == (
        "the action contains NaN or inf at indices [22 (nan), 23 (nan), 24 (nan), 25 (nan), "
        "26 (nan)] and 23 more"
    )
    dm = PlayroomMovementEnv(iterations=10)
    dm.reset(seed=0)
    with pytest.raises(ValueError) as caught:
        dm.step(_as_dm_action(action))
    assert str(caught.value) == (
        "the voice command contains NaN or inf at indices [0 (nan), 1 (nan), 2 (nan), 3 (nan), "
        "4 (nan)] and 23 more"
    )


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"grasp": "magnetic"}, "magnetic"),
        ({"iterations": 0}, "iterations must be a positive integer"),
        ({"preset": "study", "config": world_preset("study")}, "not both"),
        ({"preset": "paper"}, "unknown preset"),
        ({"seed": -1}, "seed must be a non-negative integer"),
    ],
)
def test_bad_settings_are_refused_in_one_line(kwargs, message):
    with pytest.raises(ValueError, match=message):
        PlayroomMovementEnv(**kwargs)


def test_gym_env_refuses_unknown_render_modes_reset_options_and_bad_seeds():
    with pytest.raises(
        ValueError,
        match="unknown render_mode 'ansi': one of \\['human', 'rgb_array', 'rgb_array_list'\\]",
    ):
        PlayroomGymEnv(render_mode="ansi")
    with pytest.raises(ValueError, match="unknown camera 'side'"):
        PlayroomGymEnv(render_mode="rgb_array", camera="side")
    with pytest.raises(ValueError, match="render_size 2000x100 is outside"):
        PlayroomGymEnv(render_mode="rgb_array", render_size=(2000, 100))
    env = PlayroomGymEnv(iterations=10)
    with pytest.raises(ValueError, match="no options"):
        env.reset(options={"toys": 1})
    with pytest.raises(ValueError, match="seed must be a non-negative integer"):
        env.reset(seed=-3)
