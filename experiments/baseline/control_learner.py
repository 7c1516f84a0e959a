"""The positive control's learner and what it is measured against, on any goal environment of
sim/envs (the hand's and the stick's here; one whose goal names a toy as well, for a policy of
the three toys): stable-baselines3's SAC with its HerReplayBuffer and the settings of
control_settings.py, tested on held-out goals as the environment sets them; beside it, on the
same goals, the nearest outcome among the movements the learner was given (a simpler learner on
the same data: the command whose achieved goal lies nearest the desired one, Model Babbling's
own inverse model) and random commands (the chance level). stable-baselines3 and torch (the
`rl` extra) are imported here only when a learner is built."""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

import gymnasium
import numpy as np

from experiments.baseline.control_settings import CONTROL, sac_arguments
from experiments.baseline.training import rl_library

DictObs = dict[str, np.ndarray]
Act = Callable[[DictObs], np.ndarray]
# |a| beyond this is an action at its bound (SAC's squashed actions approach +-1).
SATURATED = 0.99


def sac_her(env: gymnasium.Env, seed: int, threads: int, settings: str = CONTROL) -> Any:
    """SAC with HerReplayBuffer and the control's settings (or stable-baselines3's defaults:
    control_settings.py `sac_arguments`), on the CPU, on `env` (one goal environment; its
    episodes drawn from the model's seed)."""
    sb3 = rl_library()
    import torch

    torch.set_num_threads(threads)
    return sb3.SAC(
        "MultiInputPolicy",
        env,
        replay_buffer_class=sb3.HerReplayBuffer,
        seed=seed,
        device="cpu",
        verbose=0,
        **sac_arguments(settings),
    )


def policy_act(model: Any) -> Act:
    """The learner's deterministic action for an observation."""
    return lambda observation: model.predict(observation, deterministic=True)[0]


def nearest_outcome_act(model: Any) -> Act:
    """The command, among the movements in the learner's replay buffer so far, whose achieved
    goal (its own, not a relabelled one) lies nearest the desired goal."""
    buffer = model.replay_buffer
    n = buffer.buffer_size if buffer.full else buffer.pos
    if n == 0:
        raise ValueError("the replay buffer holds no movement yet")
    achieved = np.asarray(buffer.next_observations["achieved_goal"][:n, 0], dtype=np.float64)
    actions = np.asarray(buffer.actions[:n, 0])

    def act(observation: DictObs) -> np.ndarray:
        desired = np.asarray(observation["desired_goal"], dtype=np.float64)
        return actions[int(np.argmin(np.sum((achieved - desired) ** 2, axis=1)))]

    return act


def random_act(space: gymnasium.spaces.Box, seed: int) -> Act:
    """Uniform random commands of the action space, from a generator of `seed`."""
    rng = np.random.default_rng(seed)
    return lambda _: rng.uniform(space.low, space.high).astype(space.dtype)


@dataclass(frozen=True)
class Tested:
    """One actor on the held-out goals: the share reached, and per goal whether it was."""

    success: float
    reached: np.ndarray  # (goals,) bool
    observations: list[DictObs]
    actions: np.ndarray  # (goals, action size)


def tested(act: Act, env: gymnasium.Env, seeds: Sequence[int], tries: int = 1) -> Tested:
    """`act` given the goal of `env.reset(seed=s)` for each seed, one movement each (`tries`
    movements from the same start, each scored, for a noisy actor)."""
    reached, observations, actions = [], [], []
    for seed in seeds:
        for _ in range(tries):
            observation, _ = env.reset(seed=seed)
            action = np.asarray(act(observation))
            _, _, _, _, info = env.step(action)
            reached.append(bool(info["is_success"]))
            observations.append(observation)
            actions.append(action)
    done = np.array(reached)
    return Tested(float(done.mean()), done, observations, np.array(actions))


def critic_view(model: Any, result: Tested) -> dict[str, float]:
    """What the learner's critic says of its own actions on the held-out goals: the success it
    predicts (1 + Q, the lower of its two critics: with a reward of -1 or 0 and one movement an
    episode, Q is the expected reward), and the share of action numbers at their bound."""
    import torch

    batch = {key: np.stack([o[key] for o in result.observations]) for key in result.observations[0]}
    observations, _ = model.policy.obs_to_tensor(batch)
    with torch.no_grad():
        q = torch.min(*model.critic(observations, torch.as_tensor(result.actions)))
    return {
        "critic_success": float(1.0 + q.mean()),
        "saturated": float(np.mean(np.abs(result.actions) > SATURATED)),
    }
