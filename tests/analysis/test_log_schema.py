"""The logs' columns, declared once (experiments/trial_dir/log_schema.py): recorded logs hold them
in the declared types, a trial written before a column existed reads it as declared (missing where
it did not record it), a number computed from such a column is missing while the trial's other
numbers stay, and docs/learning.md shows the declared table."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from experiments.analysis.curves import curve_rows, grasp_rate_by_distance, tool_numbers
from experiments.analysis.logs import read_log
from experiments.analysis.mechanisms import LABELS, trial_mechanisms
from experiments.trial_dir import storage
from experiments.trial_dir.layout import CONFIG_FILE, chunk_file
from experiments.trial_dir.log_schema import (
    GOAL_COLUMNS,
    ITERATION,
    ITERATIONS,
    LEARNER_COLUMNS,
    MOTOR_SPACE,
    SOURCE_COLUMNS,
    STICK_DISTANCE,
    STICK_GRASPED,
    STICK_RETURNED,
    WORD_RECOGNISED,
    Older,
    column_names,
    column_table,
    recorded,
    upgraded,
    with_table,
)

ROOT = Path(__file__).parents[2]
DATA = ROOT / "tests" / "data"
# The reference trials' logs (tests/reference_trials.py), recorded before rows carried their
# source and the learner's values; the kinematic one before the stick's distance and returns.
KINEMATIC = DATA / "reference-kinematic-seed11-2000-iterations.parquet"
PHYSICAL = DATA / "reference-physical-seed11-2000-iterations.parquet"
CONFIG = json.loads((DATA / "config-seed7-written-at-f12e6ee.json").read_text())
WORDS = set(CONFIG["voice"]["words"])
NAMES = set(CONFIG["voice"]["words"][:3])
IMITATION = ("imitation_goals_per_name", "imitation_goals_per_distractor", "random_sound_goals")
REACH = 0.6  # m: any yardstick; the stick numbers of these logs are missing or not
DECLARED = {name: column.dtype for column in ITERATIONS for name in column.names}


def _trial(tmp_path: Path, *chunks: pd.DataFrame) -> Path:
    """A trial directory whose iterations log is these chunks, one per checkpoint period."""
    trial = tmp_path / "kinematic-seed11"
    trial.mkdir()
    storage.write_json(trial / CONFIG_FILE, {**CONFIG, "trial": {**CONFIG["trial"], "seed": 11}})
    start = 0
    for chunk in chunks:
        path = Path(trial) / chunk_file("iterations", start)
        path.parent.mkdir(parents=True, exist_ok=True)
        storage.write_table(path, chunk)
        start += len(chunk)
    return trial


def test_recorded_logs_hold_the_declared_types():
    for path in (KINEMATIC, PHYSICAL):
        log = pd.read_parquet(path)
        assert set(log.columns) <= set(DECLARED), path.name
        assert {c: str(t) for c, t in log.dtypes.items()} == {c: DECLARED[c] for c in log}


def test_an_older_trial_reads_its_missing_columns_as_declared_and_keeps_its_other_numbers(
    tmp_path,
):
    raw = pd.read_parquet(KINEMATIC)  # no stick_distance, no stick_returned, no learner values
    log = read_log(_trial(tmp_path, raw))
    assert list(log.columns) == list(column_names("iterations"))
    assert log[list(SOURCE_COLUMNS)].iloc[0].tolist() == [
        "kinematic-seed11",
        11,
        "kinematic",
        "vtl",
    ]
    # What the trial did not record is missing, never a value that counts: not False, not 0.
    assert str(log[STICK_RETURNED].dtype) == "boolean" and log[STICK_RETURNED].isna().all()
    assert log[STICK_DISTANCE].isna().all() and log[STICK_DISTANCE].dtype == np.float64
    assert log[list(LEARNER_COLUMNS)].isna().all().all()
    assert (log[list(LEARNER_COLUMNS)].dtypes == np.float32).all()
    pd.testing.assert_frame_equal(log[list(raw.columns)], raw)  # what it recorded, as it was

    numbers = trial_mechanisms(log, NAMES, WORDS)
    never = [] if raw[WORD_RECOGNISED].isin(NAMES).any() else ["first_name_recognised"]
    assert [k for k in LABELS if math.isnan(numbers[k])] == [*IMITATION, *never]
    arm = raw[raw[MOTOR_SPACE] == "arm"]
    assert numbers["stick_held"] == pytest.approx(1000 * arm[STICK_GRASPED].sum() / len(arm))
    assert sum(numbers[f"model_share_{k}"] for k in range(1, 11)) == pytest.approx(1.0)

    stick = tool_numbers(log, REACH)
    assert math.isnan(stick["stick_in_reach"]) and math.isnan(stick["stick_returns"])
    assert stick["stick_grasps_per_1000_arm"] == pytest.approx(numbers["stick_held"])
    curves = curve_rows(log, pd.DataFrame(), 2000, NAMES, REACH)
    assert set(curves["metric"]) == {"tool_use", "stick_grasp", "word_recognised"}


def test_a_trial_that_gained_a_column_is_missing_it_only_where_it_did_not_record_it(tmp_path):
    raw = pd.read_parquet(PHYSICAL)
    older = raw.iloc[:1000].drop(columns=[STICK_DISTANCE, STICK_RETURNED])
    log = read_log(_trial(tmp_path, older, raw.iloc[1000:].reset_index(drop=True)))
    returned = log[STICK_RETURNED]
    assert str(returned.dtype) == "boolean"
    assert returned.iloc[:1000].isna().all() and returned.iloc[1000:].notna().all()
    assert returned.iloc[1000:].astype(bool).tolist() == raw[STICK_RETURNED].iloc[1000:].tolist()
    # A whole-trial number cannot be told from half the trial: missing, not a count of half.
    stick = tool_numbers(log, REACH)
    assert math.isnan(stick["stick_in_reach"]) and math.isnan(stick["stick_returns"])
    # The grasp rate by distance uses the rows that say where the stick lay.
    rates = grasp_rate_by_distance(log)
    later = raw.iloc[1000:]
    assert rates["iterations"].sum() == (later[MOTOR_SPACE] == "arm").sum()


def test_a_log_that_lacks_nothing_is_read_as_it_is():
    log = pd.read_parquet(PHYSICAL)
    assert upgraded(log, "iterations", list(log.columns)) is log
    words = pd.DataFrame({ITERATION: [100], "oey": [np.inf]})
    assert upgraded(words, "words") is words  # the words are the voice's, never added


def test_a_reader_of_a_few_columns_gets_those_it_asked_for_in_its_order():
    log = pd.read_parquet(KINEMATIC)[[ITERATION, STICK_GRASPED]]
    few = upgraded(log, "iterations", [STICK_RETURNED, ITERATION, GOAL_COLUMNS[0]])
    assert list(few.columns) == [STICK_RETURNED, ITERATION, GOAL_COLUMNS[0], STICK_GRASPED]
    assert not recorded(few, [STICK_RETURNED]) and recorded(few, [ITERATION, STICK_GRASPED])


def test_a_column_older_trials_lack_reads_as_declared_in_a_type_that_holds_it():
    # Missing (never "", False or 0) where they did not record it; a declared value otherwise.
    for column in ITERATIONS:
        if column.before in (Older.ALWAYS, Older.FROM_CONFIG):
            continue
        frame = upgraded(pd.DataFrame({ITERATION: [0, 1]}), "iterations", column.names)
        for name in column.names:
            if column.before is Older.MISSING:
                assert frame[name].isna().all(), name
            else:
                assert (frame[name] == column.before).all(), name


def test_the_docs_show_the_declared_table():
    page = (ROOT / "docs" / "learning.md").read_text()
    assert with_table(page) == page, (
        "docs/learning.md's log columns differ from experiments/trial_dir/log_schema.py: run "
        "`.venv/bin/python -m experiments.trial_dir.log_schema docs/learning.md`"
    )
    assert column_table() in page
    for column in ITERATIONS:
        assert f"`{column.label}`" in column_table()
