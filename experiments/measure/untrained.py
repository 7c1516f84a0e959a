"""What the study's measure gives an agent that never learned, beside what it gives the
trials: an untrained agent has no data in any model, so in every test of the study's measure
it leaves the arm at rest (experiments/measure/study_measure.py `study_tests`), and a random
command, which now and then knocks the toy away, scores worse than that stillness. The study's
measure of such an agent is far above 0 (about 40%, beside the paper's 46%), so a page shows
it beside the trials' and says which trials score exactly as it does.

Played per trial seed (the placements follow the seed) in a fresh room of the trials' settings,
as the trial's iteration 0 had it; about 0.4 s a trial kinematic and 2 s physical, kept in the
study reference's cache (`reference_cache_dir`) like the random reference."""

from __future__ import annotations

import hashlib
import json
from pathlib import Path

import pandas as pd

from experiments.analysis.study_summary import study_summary
from experiments.measure.study_measure import (
    StudyMeasureSettings,
    code_digest,
    keep,
    read_kept,
    study_tests,
)
from experiments.run.trial_parts import fresh_trial_parts


def untrained_tests(config: dict, n_placements: int, cache: Path) -> pd.DataFrame:
    """The study's tests of a trial's agent before any learning (its config's seed fixes the
    placements), kept in `cache`."""
    key = json.dumps(
        {"config": config, "placements": n_placements, "code": code_digest()}, sort_keys=True
    )
    path = cache / f"study-untrained-{hashlib.sha256(key.encode()).hexdigest()[:16]}.parquet"
    kept = read_kept(path)
    if kept is not None:
        return kept
    agent, room = fresh_trial_parts(config)
    tests = study_tests(agent, room, StudyMeasureSettings(n_placements))
    keep(path, tests)
    return tests


def untrained_numbers(
    config: dict, trials: pd.DataFrame, tests: pd.DataFrame, reference: pd.DataFrame, cache: Path
) -> dict:
    """The study's summary of untrained agents on the trials' seeds (`trials`: one group's rows,
    with seed and n_placements); `same_as_untrained`: how many of the trials scored exactly as
    an untrained agent in every test of the study's measure (`tests`: the group's), and
    `tests_as_untrained`: the share of their tests that did."""
    pooled, same, alike, n_tests = [], 0, 0, 0
    for trial, seed, placements in trials[["trial", "seed", "n_placements"]].itertuples(
        index=False
    ):
        mine = {**config, "trial": {**config["trial"], "seed": int(seed)}}
        still = untrained_tests(mine, int(placements), cache).assign(trial=trial)
        pooled.append(still)
        played = tests[tests["trial"] == trial]
        n_tests += len(played)
        if len(played) == len(still):  # the same placements: test by test
            equal = played["error"].to_numpy() == still["error"].to_numpy()
            alike += int(equal.sum())
            same += bool(equal.all())
    summary = study_summary(pd.concat(pooled, ignore_index=True), reference)
    return {
        "competence": summary["competence"],
        "same_as_untrained": same,
        "trials": len(trials),
        "tests_as_untrained": alike / n_tests if n_tests else float("nan"),
    }
