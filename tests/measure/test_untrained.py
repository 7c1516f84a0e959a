"""Beside the study's measure of the trials, the same measure of agents that never learned
(the arm at rest in every test), and which trials scored exactly so: the study's measure gives
stillness a high score, so a page must say what an untrained agent gets."""

import os
import re
from pathlib import Path

import numpy as np
import pandas as pd

from experiments.analysis.results import collect
from experiments.analysis.study_summary import study_summary
from experiments.measure.for_reports import room_measures
from experiments.measure.study_measure import StudyMeasureSettings, random_reference, study_tests
from experiments.measure.untrained import untrained_numbers, untrained_tests
from experiments.report.batch_report import write_report
from experiments.run.trial_parts import fresh_trial_parts


def test_an_untrained_agent_leaves_the_arm_at_rest_and_is_kept(batches, tmp_path):
    results = collect(batches["kinematic"])
    config = {**results.configs["kinematic"], "trial": {**results.configs["kinematic"]["trial"]}}
    config["trial"]["seed"] = 1
    tests = untrained_tests(config, 3, tmp_path)
    agent, room = fresh_trial_parts(config)
    again = study_tests(agent, room, StudyMeasureSettings(3))
    pd.testing.assert_frame_equal(tests, again)
    assert set(tests["strategy"]) == {"hand"}  # no model has data: the arm, at rest
    assert len(list(tmp_path.glob("study-untrained-*.parquet"))) == 1


def test_trials_are_counted_untrained_only_where_every_test_scored_as_stillness(batches):
    results = collect(batches["kinematic"])
    config = results.configs["kinematic"]
    cache = Path(os.environ["PLAYROOM_CACHE_DIR"])
    reference = random_reference(
        {"kinematic": {**config, "trial": {**config["trial"], "seed": 0}}},
        StudyMeasureSettings(random_commands_per_ring=30),
        workers=1,
        progress=False,
    )["kinematic"]
    trials = results.trials
    still = pd.concat(
        [
            untrained_tests(
                {**config, "trial": {**config["trial"], "seed": int(s)}}, int(n), cache
            ).assign(trial=t)
            for t, s, n in trials[["trial", "seed", "n_placements"]].itertuples(index=False)
        ]
    )
    # Trials whose tests are the untrained agent's own: all counted, every test alike.
    numbers = untrained_numbers(config, trials, still, reference, cache)
    assert numbers["same_as_untrained"] == len(trials) and numbers["tests_as_untrained"] == 1
    assert numbers["competence"] == study_summary(still, reference)["competence"]
    # One test of one trial scored otherwise: that trial is not untrained.
    changed = still.copy()
    changed.iloc[0, changed.columns.get_loc("error")] += 0.01
    numbers = untrained_numbers(config, trials, changed, reference, cache)
    assert numbers["same_as_untrained"] == len(trials) - 1
    assert np.isclose(numbers["tests_as_untrained"], 1 - 1 / len(still))


def test_the_report_shows_the_untrained_score_beside_the_trials(batches, tmp_path):
    page = write_report(
        batches["kinematic"], tmp_path / "report", measures=room_measures(20)
    ).read_text()
    assert re.search(r"never learned.*?\d+%; \d+ of 2 trials untrained in every test", page, re.S)
