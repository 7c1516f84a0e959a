"""What a trial directory holds, and how it is read back.

A trial directory holds:
- `config.json`: every setting (trial, world, voice, learner), the package version, the seed;
- `checkpoint.npz`: agent memory, room state and every random generator state, rewritten
  every `checkpoint_every` iterations and at the end, with the one before it kept beside it
  as `checkpoint.prev.npz`: a damaged newest checkpoint costs at most two periods;
- `log/iterations-NNNNNNNN.parquet`: one row per iteration (motor space, chosen model, events),
  one file per checkpoint period, starting at iteration NNNNNNNN;
- `log/words-NNNNNNNN.parquet`: every 100 iterations, the best distance reached so far to each
  of the 6 words;
- `.lock`: the lock of its one writer (experiments/lock.py).
Everything else in it (evaluation, timing, videos) is derived from the trial at some iteration.
The writer is experiments/trial.py.
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
import pandas as pd

from experiments import storage
from experiments.lock import LOCK_FILE
from learner.agent import Agent
from learner.config import LearnerConfig
from models.layout import TOYS, context_indices
from sim import Playroom
from sim import events as ev
from sim.config import WorldConfig, config_from_dict
from sim.vocal.config import VoiceConfig

CONFIG_FILE = "config.json"
CHECKPOINT_FILE = "checkpoint.npz"
PREVIOUS_CHECKPOINT_FILE = "checkpoint.prev.npz"
# Where a damaged newest checkpoint is kept when a resume falls back past it.
DAMAGED_CHECKPOINT_FILE = "checkpoint.damaged.npz"
LOG_DIR = "log"
# What a trial directory holds of the trial itself; everything else in it (evaluation, timing,
# videos) was derived from the trial at some iteration and goes stale when it is extended.
TRIAL_ENTRIES = (
    CONFIG_FILE,
    CHECKPOINT_FILE,
    PREVIOUS_CHECKPOINT_FILE,
    DAMAGED_CHECKPOINT_FILE,
    LOG_DIR,
    LOCK_FILE,
)
STALE_PREFIX = "stale-at-"


# The agent's random generator is seeded apart from the room's, from the same trial seed.
AGENT_STREAM = 1


class TrialError(Exception):
    """A trial directory or setting that cannot be used; the message says why."""


class TrialConfigError(TrialError, ValueError):
    """A config.json no trial can be made from: a TrialError (one line, exit code 2) and a
    ValueError, as the configs raise for it (callers catching either keep working)."""


class TrialLocked(TrialError):
    """Another process is writing into the trial directory."""


def log_row(iteration: int, proposal, feedback, context: np.ndarray) -> dict:
    """One row of the iterations log: what was tried, in what context (10,), and what happened.
    `stick_distance` is the handle's distance from the arm's base before the movement (m)."""
    handle = context[list(context_indices("stick"))]
    row = {
        "iteration": iteration,
        "motor_space": proposal.motor_space,
        "model": -1 if proposal.model is None else int(proposal.model),
        "stick_distance": float(np.hypot(*handle)),
        "stick_grasped": False,
        "stick_moved_by": "",
        **{f"{toy}_moved_by": "" for toy in TOYS},
        "word_recognised": "",
        "caregiver_said": "",
        "diverged": False,
        "stick_returned": False,
    }
    for e in feedback.events:
        if e.kind == ev.STICK_GRASPED:
            row["stick_grasped"] = True
        elif e.kind == ev.STICK_MOVED:
            row["stick_moved_by"] = e.by
        elif e.kind == ev.TOY_MOVED:
            row[f"{e.obj}_moved_by"] = e.by
        elif e.kind == ev.WORD_RECOGNISED:
            row["word_recognised"] = e.word
        elif e.kind == ev.CAREGIVER_SAID:
            row["caregiver_said"] = e.word
        elif e.kind == ev.DIVERGED:
            row["diverged"] = True
        elif e.kind == ev.STICK_RETURNED:
            row["stick_returned"] = True
    return row


def fresh_trial_parts(config: dict) -> tuple[Agent, Playroom]:
    """The agent and room of a trial's iteration 0, as its config makes them. TrialConfigError
    (one line) for a config that makes none: a config.json edited by hand, or written before the
    configs checked their settings."""
    try:
        settings = config["trial"]
        room = Playroom(
            grasp=settings["grasp"],
            seed=settings["seed"],
            config=config_from_dict(WorldConfig, config["world"]),
            voice=config_from_dict(VoiceConfig, config["voice"]),
        )
        agent = Agent(
            LearnerConfig.from_dict(config["learner"]),
            np.random.default_rng([settings["seed"], AGENT_STREAM]),
        )
    except (KeyError, TypeError, ValueError) as exc:
        raise TrialConfigError(f"{CONFIG_FILE} makes no trial: {exc}") from None
    return agent, room


def restore_checkpoint(
    trial_dir: str | os.PathLike, agent: Agent, room: Playroom, name: str = CHECKPOINT_FILE
) -> dict:
    """Load a trial's checkpoint into `agent` and `room`; returns the checkpoint's metadata
    with 'best_word_distance' added. CorruptFileError if it cannot be read or restored."""
    path = Path(trial_dir) / name
    if not path.exists():
        raise storage.CorruptFileError(f"{path} is missing")
    arrays, meta = storage.read_arrays(path)
    try:
        agent_state = {
            k.removeprefix("agent/"): v for k, v in arrays.items() if k.startswith("agent/")
        }
        agent.load_state_dict(agent_state)
        room.set_state({**meta["room"], "physics": arrays["room/physics"]})
        meta["best_word_distance"] = arrays["best_word_distance"].copy()
    except (KeyError, ValueError, TypeError) as exc:
        raise storage.CorruptFileError(f"{path} cannot be restored ({exc})") from None
    return meta


def load_trial(trial_dir: str | os.PathLike) -> tuple[dict, Agent, Playroom, dict]:
    """A finished or checkpointed trial, read-only: (config, agent, room, checkpoint meta)."""
    trial_dir = Path(trial_dir)
    if not (trial_dir / CONFIG_FILE).exists():
        raise TrialError(f"{trial_dir} holds no trial ({CONFIG_FILE} is missing)")
    if not any((trial_dir / n).exists() for n in (CHECKPOINT_FILE, PREVIOUS_CHECKPOINT_FILE)):
        raise TrialError(f"{trial_dir} has no checkpoint yet")
    config = storage.read_json(trial_dir / CONFIG_FILE)
    agent, room = fresh_trial_parts(config)
    try:
        meta = restore_checkpoint(trial_dir, agent, room)
    except storage.CorruptFileError as exc:
        if (trial_dir / PREVIOUS_CHECKPOINT_FILE).exists():
            raise storage.CorruptFileError(
                f"{exc}; `playroom run --resume` continues from the previous checkpoint"
            ) from None
        raise
    return config, agent, room, meta


def read_log(trial_dir: str | os.PathLike, kind: str = "iterations") -> pd.DataFrame:
    """All chunks of one log ('iterations' or 'words') of a trial, in order."""
    chunks = sorted((Path(trial_dir) / LOG_DIR).glob(f"{kind}-*.parquet"))
    if not chunks:
        return pd.DataFrame()
    return pd.concat([storage.read_table(c) for c in chunks], ignore_index=True)
