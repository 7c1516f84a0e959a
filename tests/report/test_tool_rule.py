"""The study's tool rule beside a minimum motion of the stick (experiments/analysis/stats.py
`tool_motion`, experiments/report/tool_rule.py), on hand-made study tests."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from experiments.analysis import trial_values
from experiments.analysis.results import BatchResults
from experiments.analysis.stats import TOOL_MIN_MOTION, tool_motion
from experiments.report import differences, measure_notes
from experiments.report.measures import tool_rule_measures
from experiments.report.tool_rule import tool_motion_table


def _tests(group: str, dx: list[float], hands: int, vocal: int) -> pd.DataFrame:
    """Tool tests with the stick's x moved by each of `dx` (m), then hand and vocal tests."""
    strategies = ["tool"] * len(dx) + ["hand"] * hands + ["vocal"] * vocal
    return pd.DataFrame(
        {
            "group": group,
            "trial": f"{group}-seed0",
            "seed": 0,
            "strategy": strategies,
            "stick_dx": [*dx, *[0.0] * (hands + vocal)],
        }
    )


def _results(tests: pd.DataFrame) -> BatchResults:
    """One trial per group, holding the group's tests."""
    groups = list(dict.fromkeys(tests["group"]))
    empty = pd.DataFrame(columns=["group", "seed"])
    trials = tests[["trial", "group", "seed"]].drop_duplicates().reset_index(drop=True)
    return BatchResults(
        batch_dir=Path("."),
        trials=trials,
        competence=empty,
        vocal=empty,
        curves=empty,
        configs={g: {} for g in groups},
        study_tests=tests,
    )


# Physical: 5 tool tests, 3 of them below 1 mm either way (the sign of dx does not count);
# kinematic: 4 tool tests, one below 1 mm; a motion of exactly 1 mm is enough.
PHYSICAL = _tests("physical", [4e-9, -5e-4, 9.99e-4, 0.02, -0.3], hands=4, vocal=1)
KINEMATIC = _tests("kinematic", [TOOL_MIN_MOTION, 2e-4, 0.05, 0.1], hands=5, vocal=1)


def test_tool_uses_below_the_minimum_are_counted_and_leave_the_share():
    table = tool_motion(pd.concat([PHYSICAL, KINEMATIC])).set_index("group")
    assert table.loc["physical", ["tests", "tool", "small"]].tolist() == [10, 5, 3]
    assert table.loc["kinematic", ["tests", "tool", "small"]].tolist() == [10, 4, 1]
    assert table.loc["physical", "tool_share"] == pytest.approx(0.5)
    assert table.loc["physical", "tool_share_min_motion"] == pytest.approx(0.2)
    assert table.loc["kinematic", "tool_share_min_motion"] == pytest.approx(0.3)


def test_the_minimum_is_a_parameter():
    table = tool_motion(PHYSICAL, min_motion=1e-5).set_index("group")
    assert table.loc["physical", "small"] == 1
    assert table.loc["physical", "tool_share_min_motion"] == pytest.approx(0.4)


def test_tests_without_the_stick_motion_are_not_recorded_not_zero():
    old = PHYSICAL.drop(columns="stick_dx")
    row = tool_motion(old).iloc[0]
    assert row["tool"] == 5 and row["tool_share"] == pytest.approx(0.5)
    assert math.isnan(row["small"]) and math.isnan(row["tool_share_min_motion"])
    # A batch of old and new trials: the group's count would be a part, so none.
    mixed = pd.concat([PHYSICAL, old], ignore_index=True)
    assert math.isnan(tool_motion(mixed).iloc[0]["small"])


def test_the_pages_table_and_each_trials_shares():
    results = _results(pd.concat([PHYSICAL, KINEMATIC], ignore_index=True))
    table = tool_motion_table(results)
    assert table is not None
    rows = {row[0]: row for row in table.rows}
    assert rows["physical"][1:] == ["10", "5", "3 of 5", "50.0%", "20.0%"]
    assert rows["kinematic"][1:] == ["10", "4", "1 of 4", "40.0%", "30.0%"]
    assert "1 mm" in table.header[3]
    # The comparison's measures: each trial's shares (one trial a group here).
    small = trial_values.small_tool_uses(results).set_index("group")["value"]
    assert small["physical"] == pytest.approx(3 / 5) and small["kinematic"] == pytest.approx(1 / 4)
    shares = trial_values.study_tool_shares(results).set_index("group")
    assert shares.loc["physical", ["study's rule", "at least 1 mm"]].tolist() == [0.5, 0.2]
    assert measure_notes.small_tool_uses(results.select("physical"), TOOL_MIN_MOTION) == (
        "3 of 5 tool uses"
    )


def test_trials_without_the_stick_motion_are_not_recorded_and_not_tested():
    old = _results(PHYSICAL.drop(columns="stick_dx"))
    table = tool_motion_table(old)
    assert table is not None and table.rows[0][3] == "not recorded"
    assert trial_values.small_tool_uses(old)["value"].isna().all()
    evaluated = differences.evaluate(tuple(tool_rule_measures()), old, _results(KINEMATIC))
    for e in evaluated:
        assert e.outcomes == () and e.untested == (("", "physical: not recorded"),)
        assert differences.side_text(e.measure, old, e.values[0]) == "not recorded"
    none = _results(pd.DataFrame(columns=["group", "trial", "seed", "strategy", "stick_dx"]))
    assert tool_motion_table(none) is None


def test_study_tests_keep_the_stick_motion_their_rule_compared(trained_trial):
    from experiments.measure.study_measure import StudyMeasureSettings, study_tests
    from experiments.run.trial_parts import load_trial

    _, agent, room, _ = load_trial(trained_trial.dir)
    tests = study_tests(agent, room, StudyMeasureSettings(n_placements=2))
    arm = tests["strategy"] != "vocal"
    # The study's rule is the sign of this difference: tool exactly where it is not zero.
    assert ((tests.loc[arm, "stick_dx"] != 0) == (tests.loc[arm, "strategy"] == "tool")).all()
    assert np.isfinite(tests["stick_dx"]).all()
