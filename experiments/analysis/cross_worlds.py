"""Agents tested in the worlds they did not learn in, read back as one table: for
every trial of some batches and every test world, the trial's numbers as that world tested its
final agent, so that a difference between two conditions splits into what the agents learned
(the same test world, agents of both) and what the test world does (the same agents, both
worlds).

A trial's test in a world is its evaluation in that eval world (`DIR/eval-in-WORLD/eval.json`,
`playroom eval DIR --world WORLD`, experiments/trial_dir/eval_worlds.py) or, where that world is the
trial's own (`eval_worlds.own_world`), its own evaluation (eval.json).
Each evaluation's eval.json is checked against its own checksum and the trial's config.json
(experiments/trial_dir/eval_record.py), its tables against the sizes and SHA-256 it lists.
"""

from __future__ import annotations

import os
from pathlib import Path

import pandas as pd

from experiments.analysis.logs import trial_dirs
from experiments.trial_dir.eval_worlds import own_world
from experiments.trial_dir.reading import open_for_reading

RINGS = ("ring1", "ring2", "ring3")
STRATEGIES = ("hand", "tool", "vocal")


class MissingTestError(ValueError):
    """A trial that was not tested in a world asked for; one line names it and the command."""


def tested_in(trial_dir: Path, world: str, check: bool = True) -> tuple[dict, str]:
    """(eval.json's numbers, which evaluation: "own" or "cross") of a trial tested in `world`.
    MissingTestError where it was not; storage.CorruptFileError for an evaluation whose tables
    are not as its eval.json lists them (unless not `check`: evaluations copied without their
    tables, whose eval.json alone is read)."""
    trial = open_for_reading(trial_dir)
    config = trial.config()
    cross = trial.evaluation_elsewhere(world)
    if cross.exists():
        evaluation, which = cross, "cross"
    elif own_world(config, world):
        evaluation, which = trial.evaluation(), "own"
    else:
        raise MissingTestError(
            f"{trial_dir.name} was not tested in the {world} world: "
            f"`playroom eval {trial_dir} --world {world}`"
        )
    if not evaluation.exists():
        raise MissingTestError(f"{trial_dir.name} is not evaluated: `playroom eval {trial_dir}`")
    return checked_summary(trial_dir, evaluation.folder, config, check), which


def checked_summary(trial_dir: Path, folder: Path, config: dict, check: bool = True) -> dict:
    """The eval.json of a trial's evaluation in `folder` (the trial directory or one of its
    eval-in-WORLD/), checked against itself and the trial's `config` (experiments/
    eval_record.py) and, if `check`, each table it lists against it. storage.CorruptFileError
    (one line naming the file and what to do) otherwise."""
    evaluation = open_for_reading(trial_dir).evaluation(folder)
    summary = evaluation.summary(config)
    if check:
        evaluation.check_tables(summary)
    return summary


def cross_table(batches: dict[str, str | os.PathLike], worlds: tuple[str, ...]) -> pd.DataFrame:
    """One row per (condition, trial, test world): `condition` (the key of `batches`, a batch
    directory each), seed, the trial's backend, `world`, `evaluation` (own or cross), the
    project's normalised competence (all, ring1-3) and each ring's strategy shares. Every trial
    of every batch must have been tested in every world (MissingTestError otherwise)."""
    rows = []
    for condition, batch_dir in batches.items():
        for trial_dir in trial_dirs(batch_dir):
            for world in worlds:
                summary, which = tested_in(trial_dir, world)
                row = {
                    "condition": condition,
                    "trial": trial_dir.name,
                    "seed": summary["seed"],
                    "grasp": summary["grasp"],
                    "world": world,
                    "evaluation": which,
                    **{f"competence_{k}": v for k, v in summary["competence"].items()},
                }
                for ring in RINGS:
                    shares = summary["strategy_share"].get(ring, {})
                    for strategy in STRATEGIES:
                        row[f"{strategy}_{ring}"] = float(shares.get(strategy, 0.0))
                rows.append(row)
    return pd.DataFrame(rows)
