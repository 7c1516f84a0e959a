"""The Gymnasium ids as a user makes them (sim/envs/versions.py): the command line's names for
the world, the registered variants and their documented versions, float32 spaces, and an episode
length that `spec.max_episode_steps` tells."""

from __future__ import annotations

import re

import gymnasium
import numpy as np
import pytest
from gymnasium.error import DeprecatedEnv

from models.layout import block_slice
from sim.config import world_preset
from sim.envs import DIVA_ID, GYM_ID, PHYSICAL_ID, PlayroomGymEnv
from sim.envs.versions import STUDY_ITERATIONS, VARIANTS
from sim.vocal.config import VoiceConfig
from sim.vocal.diva import data

VOICE = np.r_[1.0, np.zeros(21), np.full(28, 0.3)].astype(np.float32)  # a[0] >= 0: the voice


# The command line's names -------------------------------------------------------------------
def test_make_takes_the_command_lines_names_for_the_world():
    env = gymnasium.make(GYM_ID, grasp="physical", voice="vtl", preset="project")
    room = env.unwrapped.movement_env.room
    assert room.grasp == "physical" and room.vocal_tract.name == "vtl"
    assert room.config == world_preset("project")


def test_the_diva_voice_by_name_speaks_with_the_installed_map(installed_generated_map):
    env = gymnasium.make(f"sim.envs:{GYM_ID}", voice="diva")
    env.reset(seed=0)
    obs, _, _, _, info = env.step(VOICE)
    assert env.unwrapped.movement_env.room.vocal_tract.name == "diva"
    assert info["motor_space"] == "voice"
    sound = obs[block_slice("sound")]
    assert np.isfinite(sound).all() and np.abs(sound).max() > 0


def test_the_diva_voice_without_its_data_says_how_to_install_it(tmp_path, monkeypatch):
    monkeypatch.setenv(data.DATA_ENV, str(tmp_path))  # nothing installed there
    with pytest.raises(data.DivaDataMissing, match="playroom voice-data diva PATH"):
        gymnasium.make(DIVA_ID)


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"voice": "klatt"}, "^unknown voice 'klatt': one of vtl, diva$"),
        ({"voice": VoiceConfig()}, "voice is the vocal tract's name.*are voice_config\\)$"),
        ({"voice_config": "diva"}, "^voice_config must be a VoiceConfig, got a str$"),
        ({"grasp": "magnetic"}, "^unknown grasp backend 'magnetic'"),
        ({"preset": "paper"}, "^unknown preset 'paper'"),
    ],
)
def test_unknown_names_are_refused_in_one_line(kwargs, message):
    with pytest.raises(ValueError, match=message) as caught:
        gymnasium.make(GYM_ID, **kwargs)
    assert "\n" not in str(caught.value)


# Registered variants and their documentation ------------------------------------------------
@pytest.mark.parametrize("env_id", [GYM_ID, PHYSICAL_ID, DIVA_ID])
def test_each_variant_is_registered_with_its_world_and_the_studys_episode_length(
    env_id, installed_generated_map
):
    env = gymnasium.make(f"sim.envs:{env_id}")
    room = env.unwrapped.movement_env.room
    expected = {"grasp": "kinematic", "voice": "vtl", **VARIANTS[env_id]}
    assert (room.grasp, room.vocal_tract.name) == (expected["grasp"], expected["voice"])
    assert env.spec.max_episode_steps == STUDY_ITERATIONS == 80000


def test_the_first_version_is_refused_with_the_current_one():
    with (
        pytest.warns(DeprecationWarning, match="out of date"),
        pytest.raises(DeprecatedEnv, match="Please use `Playroom-v1` instead"),
    ):
        gymnasium.make("sim.envs:Playroom-v0")


def _table(doc: str, section: str) -> list[tuple[range, float, float]]:
    """The rows of a docstring table: (indices, min, max)."""
    text = doc.split(f"## {section}")[1].split("##")[0]
    rows = re.findall(r"^\s*\| (\d+)(?:-(\d+))? +\|[^|]+\| +(\S+) +\| +(\S+) +\|$", text, re.M)
    return [(range(int(a), int(b or a) + 1), float(lo), float(hi)) for a, b, lo, hi in rows]


@pytest.mark.parametrize(
    ("section", "space"),
    [("Action Space", "action_space"), ("Observation Space", "observation_space")],
)
def test_the_docstrings_tables_name_every_entry_with_the_spaces_bounds(section, space):
    box = getattr(PlayroomGymEnv(iterations=2), space)
    rows = _table(PlayroomGymEnv.__doc__ or "", section)
    assert [i for indices, _, _ in rows for i in indices] == list(range(box.shape[0]))
    for indices, low, high in rows:
        np.testing.assert_allclose(box.low[list(indices)], low, rtol=1e-6)
        np.testing.assert_allclose(box.high[list(indices)], high, rtol=1e-6)


def test_the_version_history_names_every_version_and_variant():
    doc = PlayroomGymEnv.__doc__ or ""
    for section in ("Description", "Rewards", "Episode End", "Arguments", "Version History"):
        assert f"## {section}" in doc
    history = doc.split("## Version History")[1]
    assert "* v1:" in history and "* v0:" in history
    assert all(env_id in doc for env_id in VARIANTS if env_id != GYM_ID)


# Spaces and episode length ------------------------------------------------------------------
def test_spaces_and_observations_are_float32_the_room_float64_inside():
    env = gymnasium.make(GYM_ID)
    assert env.action_space.dtype == env.observation_space.dtype == np.float32
    obs, _ = env.reset(seed=0)
    assert obs.dtype == np.float32 and obs in env.observation_space
    obs, *_ = env.step(env.action_space.sample())
    assert obs.dtype == np.float32 and obs in env.observation_space
    feedback = env.unwrapped.movement_env.last_feedback
    assert feedback.s.dtype == np.float64
    np.testing.assert_array_equal(obs[10:], feedback.s.astype(np.float32))


def test_time_limit_ends_the_episode_that_max_episode_steps_declares():
    env = gymnasium.make(GYM_ID, max_episode_steps=3)
    assert env.spec.max_episode_steps == 3
    env.reset(seed=0)
    ends = [env.step(env.action_space.sample())[2:4] for _ in range(3)]
    assert ends == [(False, False), (False, False), (False, True)]


def test_make_refuses_iterations_for_the_length_it_would_not_declare():
    with pytest.raises(ValueError, match="give max_episode_steps=5, not iterations$"):
        gymnasium.make(GYM_ID, iterations=5)
