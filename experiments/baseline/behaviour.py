"""What a baseline's toy policies do in the goal environments they were trained in, against
uniform random actions there (`playroom rl-behaviour`): per toy and actor, over the same
episodes (the same rooms and goals, from the same reset seeds), the share of movements that
were the voice (`a[0] >= 0`), that moved the goal toy (its achieved goal changed) and that
reached the goal (reward 0). The test says how well a policy scores; this says what it does
and what its training signal looked like: the goal is reached, and the toy moved, about as
often as random actions reach and move it (docs/rl-baseline.md)."""

from __future__ import annotations

import os
from collections.abc import Callable, Iterable
from dataclasses import asdict, dataclass
from pathlib import Path

import numpy as np

from experiments.baseline import training
from experiments.baseline.run import policy_file, trained_toys
from experiments.baseline.settings import BaselineError
from experiments.run.trial_parts import fresh_trial_parts
from experiments.trial_dir import storage
from experiments.trial_dir.baseline_run import open_baseline_run
from sim.config import config_from_dict
from sim.vocal.config import VoiceConfig

# Episodes' reset seeds start here, apart from the seeds training drew its rooms from.
FIRST_EPISODE_SEED = 10_000


@dataclass(frozen=True)
class Behaviour:
    """One actor's movements on one toy's goal environment; shares in [0, 1]."""

    run: str
    toy: int
    actor: str
    movements: int
    voice: float
    moved: float
    reached: float


def tally(
    env: training.SameWords, act: Callable[[dict], np.ndarray], episodes: int
) -> tuple[int, float, float, float]:
    """(movements, voice share, moved share, reached share) of `act` (observation -> action)
    over `episodes` episodes of `env`, reset from FIRST_EPISODE_SEED on."""
    voice = moved = reached = n = 0
    for episode in range(episodes):
        observation, _ = env.reset(seed=FIRST_EPISODE_SEED + episode)
        done = False
        while not done:
            action = act(observation)
            before = observation["achieved_goal"].copy()
            observation, reward, terminated, truncated, _ = env.step(action)
            voice += bool(action[0] >= 0)
            moved += not np.array_equal(observation["achieved_goal"], before)
            reached += reward == 0
            n += 1
            done = terminated or truncated
    return n, voice / n, moved / n, reached / n


def run_behaviour(run_dir: str | os.PathLike, episodes: int) -> list[Behaviour]:
    """Every trained toy policy of a baseline run, and random actions on the same episodes."""
    out = Path(run_dir)
    run = open_baseline_run(out)
    if not run.is_run():
        raise BaselineError(f"{out} holds no baseline run ({run.record_path.name} is missing)")
    toys = trained_toys(out)  # their files checked against training.json
    if not toys:
        raise BaselineError(f"{out}: no toy policy trained yet")
    config = storage.read_json(run.record_path)["trial"]
    _, room = fresh_trial_parts(config)
    voice = config_from_dict(VoiceConfig, config["voice"])
    grasp = config["trial"]["grasp"]
    found = []
    for toy in sorted(int(t) for t in toys):
        env = training.make_env(grasp, toy, room.config, voice, room.words)
        model = training.load_policy((out / policy_file(toy)).read_bytes(), env)
        for actor, act in _actors(model, env, toy).items():
            found.append(Behaviour(out.name, toy, actor, *tally(env, act, episodes)))
        env.close()
    return found


def _actors(model, env: training.SameWords, toy: int) -> dict[str, Callable[[dict], np.ndarray]]:
    """The policy, deterministic, and uniform random actions from a generator of the toy."""
    rng = np.random.default_rng(toy)
    shape = env.action_space.shape
    return {
        "policy": lambda observation: model.predict(observation, deterministic=True)[0],
        "random": lambda _: rng.uniform(-1.0, 1.0, shape).astype(np.float32),
    }


def as_rows(behaviours: Iterable[Behaviour]) -> list[dict]:
    return [asdict(b) for b in behaviours]
