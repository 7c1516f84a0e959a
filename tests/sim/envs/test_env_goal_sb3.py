"""The goal-conditioned environments in a real reinforcement-learning library: stable-baselines3's
`check_env` takes what `gymnasium.make` gives for each id, whole; SAC with its HerReplayBuffer,
every default kept, builds from each id (both grasp backends), relabels with the environment's
`compute_reward` and learns a few hundred steps without error. Not a performance claim: nothing
here says it learns to reach goals (the positive control does: tests/baseline/).

`make test-slow` installs the `rl` extra (pyproject.toml) and runs these; elsewhere they are
skipped where stable-baselines3 is not installed, with the reason."""

from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from rl_extra import require_stable_baselines3

from sim.envs import GOAL_VARIANTS

require_stable_baselines3()

import gymnasium  # noqa: E402
from stable_baselines3 import SAC, HerReplayBuffer  # noqa: E402
from stable_baselines3.common.env_checker import check_env  # noqa: E402

pytestmark = pytest.mark.slow

DOCS = Path(__file__).resolve().parents[3] / "docs" / "environments.md"
# SAC's default learning_starts is 100: 300 steps are 200 gradient steps on relabelled batches.
STEPS = 300


@pytest.mark.parametrize("env_id", list(GOAL_VARIANTS))
def test_stable_baselines_check_env_takes_what_make_gives_whole(env_id):
    # v0's TimeLimit failed here: "'TimeLimit' object has no attribute 'compute_reward'".
    check_env(gymnasium.make(f"sim.envs:{env_id}"))


@pytest.mark.parametrize("env_id", list(GOAL_VARIANTS))
def test_sac_with_her_and_its_defaults_learns_on_each_goal_id(env_id):
    model = SAC(
        "MultiInputPolicy",
        f"sim.envs:{env_id}",
        replay_buffer_class=HerReplayBuffer,
        seed=0,
        device="cpu",
    )
    model.learn(STEPS)
    assert model.num_timesteps == STEPS
    buffer = model.replay_buffer
    assert isinstance(buffer, HerReplayBuffer) and buffer.n_sampled_goal == 4  # its defaults
    # Relabelled batches, rewards from the environment's compute_reward: HER's future goals
    # are achieved ones, so some rewards are successes (0) among the failures (-1).
    batch = buffer.sample(256)
    rewards = batch.rewards.numpy().ravel()
    assert set(np.unique(rewards)) == {-1.0, 0.0}
    room = model.env.envs[0].unwrapped.playroom.movement_env.room
    assert room.grasp == GOAL_VARIANTS[env_id].get("grasp", "kinematic")


def test_the_docs_sac_and_her_example_runs_as_written(tmp_path):
    page = DOCS.read_text()
    section = page.split("## Goal-conditioned environments")[1]
    code = re.search(r"```python\n(.*?)```", section, re.S)
    assert code is not None and "HerReplayBuffer" in code.group(1)
    result = subprocess.run(
        [sys.executable, "-c", code.group(1)], capture_output=True, text=True, cwd=tmp_path
    )
    assert result.returncode == 0, result.stderr[-2000:]
