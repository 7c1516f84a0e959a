"""Training one toy's policy: stable-baselines3's SAC with its HerReplayBuffer, every default of
theirs kept, on the toy-goal environment of sim/envs (PlayroomGoalEnv, `goal="toyK"`) in the
world of the baseline's trial. stable-baselines3 and torch (the `rl` extra) are imported here,
when a policy is trained or loaded, never when the package is: `rl_library` names the extra in
one line where they are missing.

The environment is the registered one, with one thing held: every episode's room keeps the
caregiver's words of the trial's room (`SameWords`). The goal environments build a new room for
each episode, whose words are drawn anew, so that a toy's name would change from episode to
episode; the Model Babbling agent lives in one room, whose names never change, and is tested
in it. With the same words, a name said brings the same toy in training and in the tests, for
both learners.
"""

from __future__ import annotations

import io
import time
from typing import Any

import numpy as np
from tqdm import tqdm

from sim.process_environment import environment_kept

# Gymnasium sets PYGAME_HIDE_SUPPORT_PROMPT when first imported; importing the project's
# packages changes no environment variable (sim/envs/__init__.py does the same).
with environment_kept():
    import gymnasium

from experiments.baseline.settings import (
    ALGORITHM,
    EPISODE_MOVEMENTS,
    MOTOR,
    POLICY,
    REPLAY_BUFFER,
    BaselineError,
)
from models.layout import block_slice
from sim.caregiver import WordAssignment
from sim.config import WorldConfig
from sim.envs.versions import GOAL_VARIANTS
from sim.vocal.config import VoiceConfig

RL_EXTRA = "make install-rl"
_SOUND = block_slice("sound")
# The SAC settings that baseline's training.json records (their values are the library's).
RECORDED = (
    "learning_rate",
    "buffer_size",
    "learning_starts",
    "batch_size",
    "tau",
    "gamma",
    "train_freq",
    "gradient_steps",
    "ent_coef",
    "target_update_interval",
    "target_entropy",
    "policy_kwargs",
)


def rl_library() -> Any:
    """stable_baselines3, imported; BaselineError (one line) where the `rl` extra is missing."""
    try:
        import stable_baselines3
        import torch  # noqa: F401  (stable-baselines3's own dependency: named if broken)
    except ImportError as exc:
        raise BaselineError(
            f"the RL baseline needs the `rl` extra (stable-baselines3, torch): {RL_EXTRA} "
            f"(stable-baselines3 and torch's CPU build into .venv); {exc}"
        ) from None
    return stable_baselines3


def goal_id(grasp: str) -> str:
    """The registered toy-goal id of a grasp backend (sim/envs/versions.py)."""
    (found,) = [
        name
        for name, kwargs in GOAL_VARIANTS.items()
        if kwargs["goal"] == "toy1" and kwargs.get("grasp", "kinematic") == grasp
    ]
    return found


class SameWords(gymnasium.Wrapper):
    """Every episode's room keeps `words` (the module's docstring); the best distance of the
    learner's own sounds to each word is kept as a trial keeps it (`best_word_distance`, in the
    order of the voice's words), for the vocal table of its evaluation."""

    def __init__(self, env: gymnasium.Env, words: WordAssignment) -> None:
        super().__init__(env)
        self.words = words
        self.best_word_distance = np.full(
            len(words.names) + len(words.distractors), np.inf, dtype=float
        )

    def _room(self) -> Any:
        return self.env.unwrapped.playroom.movement_env.room  # type: ignore[attr-defined]

    def reset(self, **kwargs: Any) -> Any:
        observation, info = self.env.reset(**kwargs)
        self._room().caregiver.words = self.words
        return observation, info

    def step(self, action: Any) -> Any:
        observation, reward, terminated, truncated, info = self.env.step(action)
        if info["motor_space"] == "voice":
            room = self._room()
            feedback = self.env.unwrapped.playroom.movement_env.last_feedback  # type: ignore[attr-defined]
            distances = room.vocal_tract.word_distances(feedback.s[_SOUND])
            np.minimum(self.best_word_distance, distances, out=self.best_word_distance)
        return observation, reward, terminated, truncated, info


def make_env(
    grasp: str, toy: int, world: WorldConfig, voice: VoiceConfig, words: WordAssignment
) -> SameWords:
    """The toy-goal environment of toy `toy` (1-3) in the trial's world, its words held."""
    import sim.envs  # noqa: F401  (registers the ids)

    env = gymnasium.make(
        goal_id(grasp),
        goal=f"toy{toy}",
        motor=MOTOR,
        movements=EPISODE_MOVEMENTS,
        grasp=grasp,
        config=world,
        voice_config=voice,
    )
    return SameWords(env, words)


def train_policy(
    env: SameWords, steps: int, seed: int, threads: int, bar: tqdm | None = None
) -> tuple[bytes, dict[str, Any]]:
    """(the trained model's zip, its record: steps, seconds, the SAC settings, the best word
    distances) of SAC + HER trained `steps` movements on `env` from `seed`."""
    sb3 = rl_library()
    import torch
    from stable_baselines3.common.callbacks import BaseCallback

    torch.set_num_threads(threads)

    class Progress(BaseCallback):
        def _on_step(self) -> bool:
            if bar is not None:
                bar.update(1)
            return True

    model = getattr(sb3, ALGORITHM)(
        POLICY,
        env,
        replay_buffer_class=getattr(sb3, REPLAY_BUFFER),
        seed=seed,
        device="cpu",
        verbose=0,
    )
    start = time.perf_counter()
    model.learn(steps, callback=Progress())
    seconds = time.perf_counter() - start
    buffer = io.BytesIO()
    model.save(buffer)
    record = {
        "steps": int(model.num_timesteps),
        "seconds": round(seconds, 3),
        "sac": {name: str(getattr(model, name, None)) for name in RECORDED},
        "her": {
            "n_sampled_goal": int(model.replay_buffer.n_sampled_goal),
            "goal_selection_strategy": str(model.replay_buffer.goal_selection_strategy),
        },
        "best_word_distance": [float(d) for d in env.best_word_distance],
    }
    env.close()
    return buffer.getvalue(), record


def load_policy(data: bytes, env: SameWords) -> Any:
    """A saved policy (the zip `train_policy` gives), on the CPU, with the environment it was
    trained on (stable-baselines3 loads a model of HerReplayBuffer only with one)."""
    sb3 = rl_library()
    return getattr(sb3, ALGORITHM).load(io.BytesIO(data), env=env, device="cpu")


def library_versions() -> dict[str, str | None]:
    """The versions of the libraries a baseline's numbers depend on besides the project's."""
    from importlib.metadata import PackageNotFoundError, version

    out: dict[str, str | None] = {}
    for name in ("stable-baselines3", "torch", "gymnasium"):
        try:
            out[name] = version(name)
        except PackageNotFoundError:
            out[name] = None
    return out
