"""The Gymnasium environment in a real reinforcement-learning library, stable-baselines3, with
its defaults: it builds environments from the id and asks for render_mode="rgb_array".

`make test-slow` installs the `rl` extra (pyproject.toml; it brings torch) and runs these; in
any other run they are skipped where stable-baselines3 is not installed, with the reason."""

from __future__ import annotations

import numpy as np
import pytest
from rl_extra import require_stable_baselines3

from sim.envs import GYM_ID

ENV_ID = f"sim.envs:{GYM_ID}"
require_stable_baselines3()

import stable_baselines3  # noqa: E402
from stable_baselines3 import PPO  # noqa: E402
from stable_baselines3.common.env_checker import check_env  # noqa: E402
from stable_baselines3.common.env_util import make_vec_env  # noqa: E402

pytestmark = pytest.mark.slow


def test_stable_baselines_checker_passes():
    import gymnasium

    env = gymnasium.make(ENV_ID, max_episode_steps=10)
    check_env(env.unwrapped)  # raises on what SB3 cannot use; its advice only warns


def test_make_vec_env_builds_from_the_id_and_renders_frames():
    vec = make_vec_env(ENV_ID, n_envs=2, seed=0)
    assert vec.render_mode == "rgb_array"  # SB3's default when it builds from an id
    observations = vec.reset()
    assert observations.shape == (2, 70)
    observations, rewards, dones, infos = vec.step(np.zeros((2, 50)))
    assert observations.shape == (2, 70) and not dones.any()
    frames = vec.get_images()
    vec.close()
    assert [f.shape for f in frames] == [(480, 640, 3)] * 2
    assert all(len(np.unique(f.reshape(-1, 3), axis=0)) > 50 for f in frames)


def test_ppo_builds_from_the_id_with_its_defaults_and_learns():
    PPO("MlpPolicy", ENV_ID)  # every default: the environment made with render_mode="rgb_array"
    # A short run: one rollout of 256 steps, then PPO's 10 epochs over it.
    model = PPO("MlpPolicy", ENV_ID, n_steps=256, batch_size=64, seed=0, device="cpu")
    model.learn(256)
    assert model.num_timesteps == 256
    assert stable_baselines3.__version__.startswith("2.")
    action, _ = model.predict(model.env.reset(), deterministic=True)
    assert action.shape == (1, 50)
