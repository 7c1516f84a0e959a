"""What a trial directory holds, and how it is read back.

A trial directory holds:
- `config.json`: every setting (trial, world, voice, learner), the package version, the seed;
- `checkpoint.npz`: the agent's state, the room's and every random generator's, rewritten
  every `checkpoint_every` iterations and at the end, with the one before it kept beside it
  as `checkpoint.prev.npz`: a damaged newest checkpoint costs at most two periods;
- `memory/rows-NNNNNNNN.npz`: the rows the models' memories stored over the checkpoint period
  starting at iteration NNNNNNNN, each row written once, before the checkpoint that names the
  segments it is made of (experiments/run/memory_segments.py; checkpoints written before
  segments hold every row themselves);
- `log/iterations/chunk-NNNNNNNN.parquet`: one row per iteration (motor space, chosen model,
  events, goal, outcome, every model's interest), one file per checkpoint period, starting at
  iteration NNNNNNNN;
- `log/words/chunk-NNNNNNNN.parquet`: every 100 iterations, the best distance reached so far to
  each of the 6 words, in the chunk of the period that reaches them;
  every row of both carries its source (trial, seed, backend, voice), and every chunk its
  trial's identity, as checkpoints do; where the chunks lie is experiments/log_layout.py and
  what every column holds experiments/log_schema.py, which this writer and every reader follow
  (trials of the old layout too: log/iterations-NNNNNNNN.parquet and log/words-NNNNNNNN.parquet
  side by side);
- `log/README.txt`: which folder of log/ to read (a reader of all of log/ stops on it);
- `provenance.json`: the machine, libraries and commit that computed each stretch of
  iterations, one entry per run or resume (experiments/provenance.py);
- `backend.json`: what the grasp backend declares of itself (its reach, its capabilities),
  written when the trial first computes (experiments/backend_record.py);
- `.lock`: the lock of its one writer (experiments/run/lock.py).
Everything else in it (evaluation, timing, videos) is derived from the trial at some iteration.
The writer is experiments/run/trial.py; experiments/run/trial_checks.py reads a trial back only
when it is whole (its checkpoint its own and readable, the logs it covers complete).
"""

from __future__ import annotations

import numpy as np

from experiments.file_names import CONFIG_FILE
from experiments.log_schema import (
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
from learner.agent import Agent, Proposal
from learner.config import LearnerConfig
from models.layout import BLOCK_DIM, context_indices
from sim import Playroom
from sim import events as ev
from sim.config import WorldConfig, config_from_dict
from sim.vocal.config import VoiceConfig

# Iterations between two rows of the words log: the vocal learning curves are read every 100
# iterations (docs/protocol.md §10).
WORDS_LOG_PERIOD = 100

# What log/README.txt says (experiments/file_names.py: why it is there).
LOG_README = """\
This folder holds a trial's logs, one folder per kind, one Parquet chunk per checkpoint period:
  iterations/  one row per iteration          pd.read_parquet("TRIAL/log/iterations")
  words/       every 100 iterations, the best distance reached so far to each word
                                              pd.read_parquet("TRIAL/log/words")
The kinds have different rows: read one of the folders, not this one (this file stops a reader
of the whole folder before it mixes them). Every row names its trial, seed, backend and voice.
With the project installed: `from experiments.analysis.logs import read_log, read_batch_logs`;
the columns are described in experiments/log_schema.py.
"""

_NO_BLOCK = np.full(BLOCK_DIM, np.nan)


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
        raise TrialConfigError(f"{CONFIG_FILE} makes no trial: {exc}") from None


def trial_parts(
    grasp: str, seed: int, world: WorldConfig, voice: VoiceConfig, learner: LearnerConfig
) -> tuple[Agent, Playroom]:
    """The agent and room of a trial's iteration 0 from its typed configs."""
    room = Playroom(grasp=grasp, seed=seed, config=world, voice=voice)
    agent = Agent(learner, np.random.default_rng([seed, AGENT_STREAM]))
    return agent, room
