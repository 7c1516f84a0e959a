"""A trial's parts and rows: the agent and room of its iteration 0, built from its typed
settings or from its config.json (`trial_parts`, `fresh_trial_parts`), and the row of the
iterations log each iteration makes (`log_row`, `learner_values`), whose columns
experiments/trial_dir/log_schema.py declares.
"""

from __future__ import annotations

import os

import numpy as np

from experiments.trial_dir.errors import TrialConfigError
from experiments.trial_dir.log_schema import (
    CAREGIVER_SAID,
    DIVERGED,
    EMPTY_ROW,
    ITERATION,
    MODEL,
    MOTOR_SPACE,
    STICK_DISTANCE,
    STICK_GRASPED,
    STICK_MOVED_BY,
    STICK_RETURNED,
    WORD_RECOGNISED,
    moved_by,
)
from experiments.trial_dir.reading import open_for_reading
from learner.agent import Agent, Proposal
from learner.config import LearnerConfig
from models.layout import BLOCK_DIM, context_indices
from sim import Playroom
from sim import events as ev
from sim.config import WorldConfig, config_from_dict
from sim.vocal.config import VoiceConfig

_NO_BLOCK = np.full(BLOCK_DIM, np.nan)


# The agent's random generator is seeded apart from the room's, from the same trial seed.
AGENT_STREAM = 1


def log_row(iteration: int, proposal, feedback, context: np.ndarray) -> dict:
    """One row of the iterations log: what was tried, in what context (10,), and what happened.
    `stick_distance` is the handle's distance from the arm's base before the movement (m)."""
    x, y = context_indices("stick")
    row = dict(EMPTY_ROW)  # every event column, as if nothing happened
    row[ITERATION] = iteration
    row[MOTOR_SPACE] = proposal.motor_space
    row[MODEL] = -1 if proposal.model is None else int(proposal.model)
    row[STICK_DISTANCE] = float(np.hypot(context[x], context[y]))
    for e in feedback.events:
        if e.kind == ev.STICK_GRASPED:
            row[STICK_GRASPED] = True
        elif e.kind == ev.STICK_MOVED:
            row[STICK_MOVED_BY] = e.by
        elif e.kind == ev.TOY_MOVED:
            row[moved_by(e.obj)] = e.by
        elif e.kind == ev.WORD_RECOGNISED:
            row[WORD_RECOGNISED] = e.word
        elif e.kind == ev.CAREGIVER_SAID:
            row[CAREGIVER_SAID] = e.word
        elif e.kind == ev.DIVERGED:
            row[DIVERGED] = True
        elif e.kind == ev.STICK_RETURNED:
            row[STICK_RETURNED] = True
    return row


def learner_values(
    proposal: Proposal, reached: np.ndarray | None, interests: np.ndarray
) -> np.ndarray:
    """The learner's columns of an iteration's row (log_schema.LEARNER_COLUMNS), (30,): the goal
    (NaN without one: the bootstrap's random motor babbling), the outcome in the goal's block
    (`Agent.outcome`, NaN without a model) and each model's interest when the model was
    chosen (`Agent.interests`, read before the iteration's attempt)."""
    return np.concatenate(
        (
            _NO_BLOCK if proposal.goal is None else proposal.goal,
            _NO_BLOCK if reached is None else reached,
            interests,
        )
    )


def fresh_trial_parts(config: dict) -> tuple[Agent, Playroom]:
    """The agent and room of a trial's iteration 0, as its config (config.json's form) makes
    them. TrialConfigError (one line) for a config that makes none: a config.json edited by
    hand, or written before the configs checked their settings."""
    try:
        settings = config["trial"]
        return trial_parts(
            settings["grasp"],
            settings["seed"],
            config_from_dict(WorldConfig, config["world"]),
            config_from_dict(VoiceConfig, config["voice"]),
            LearnerConfig.from_dict(config["learner"]),
        )
    except (KeyError, TypeError, ValueError) as exc:
        raise TrialConfigError.making_no_trial(exc) from None


def trial_parts(
    grasp: str, seed: int, world: WorldConfig, voice: VoiceConfig, learner: LearnerConfig
) -> tuple[Agent, Playroom]:
    """The agent and room of a trial's iteration 0 from its typed configs."""
    room = Playroom(grasp=grasp, seed=seed, config=world, voice=voice)
    agent = Agent(learner, np.random.default_rng([seed, AGENT_STREAM]))
    return agent, room


def load_trial(trial_dir: str | os.PathLike) -> tuple[dict, Agent, Playroom, dict]:
    """A finished or checkpointed trial, read-only: (config, agent, room, checkpoint meta), its
    agent and room built from its config.json and restored from its newest checkpoint, the
    trial checked whole first (experiments/trial_dir/reading.py `TrialReading.restored`:
    TrialError otherwise)."""
    return open_for_reading(trial_dir).restored(fresh_trial_parts)
