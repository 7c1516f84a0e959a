"""The study's strategies split by the name of the tested toy
(experiments/report/name_strategies.py)."""

from __future__ import annotations

import dataclasses
import shutil

import pandas as pd
import pytest
from old_trials import as_evaluated_before_names_had_toys

from experiments.analysis.results import collect
from experiments.measure.for_reports import room_measures
from experiments.report.batch_report import write_report
from experiments.report.name_strategies import (
    NOT_RECORDED,
    name_strategy_table,
    named_tests,
    strategy_shares,
)
from experiments.trial_dir.layout import EVAL_FILE


def _results(batches) -> object:
    return collect(batches["kinematic"])


def _two_trials(batches):
    """The tiny kinematic batch with hand-made tests and words: trial A names toy 1 'iuo'
    (said, 0.2) and toy 2 'yeo' (not said, 0.6); trial B names toy 1 'yeo' (said, 0.3)."""
    results = _results(batches)
    a, b = sorted(results.trials["trial"])
    group = results.groups[0]
    tests = pd.DataFrame(
        [
            # trial, toy, ring, strategy
            (a, 1, 1, "vocal"),
            (a, 1, 1, "hand"),
            (a, 1, 3, "vocal"),
            (a, 2, 1, "hand"),
            (a, 2, 3, "tool"),
            (a, 3, 3, "hand"),  # toy 3 named by no word of this table: left out
            (b, 1, 3, "vocal"),
            (b, 1, 3, "hand"),
        ],
        columns=["trial", "toy", "ring", "strategy"],
    ).assign(group=group, x=0.0, y=0.0, error=0.5)
    vocal = pd.DataFrame(
        [
            (a, "iuo", True, 1, 0.2),
            (a, "yeo", True, 2, 0.6),
            (a, "eou", False, 0, 0.1),  # a distractor said well: not a name
            (b, "yeo", True, 1, 0.3),
        ],
        columns=["trial", "word", "is_name", "toy", "best_distance"],
    ).assign(group=group)
    return dataclasses.replace(results, study_tests=tests, vocal=vocal), group


def test_tests_take_the_name_of_their_toy_and_whether_it_was_said(batches):
    results, _ = _two_trials(batches)
    named = named_tests(results, threshold=0.4)
    assert len(named) == 7  # toy 3 of trial A has no name in this table
    assert set(named.loc[named["word"] == "iuo", "said"]) == {True}
    yeo = named[named["word"] == "yeo"]
    assert yeo.groupby("trial")["said"].first().tolist() == [False, True]
    assert (named.loc[named["word"] == "eou"]).empty


def test_shares_are_per_word_and_ring(batches):
    results, group = _two_trials(batches)
    shares = strategy_shares(named_tests(results, 0.4), ["group", "word"]).set_index(
        ["word", "ring"]
    )
    assert shares.loc[("iuo", 1), "vocal"] == pytest.approx(0.5)
    assert shares.loc[("iuo", 1), "tests"] == 2 and shares.loc[("iuo", 1), "toys"] == 1
    # yeo in ring 3: trial A's tool test and trial B's vocal and hand tests, two toys.
    assert shares.loc[("yeo", 3), ["hand", "tool", "vocal"]].tolist() == pytest.approx(
        [1 / 3, 1 / 3, 1 / 3]
    )
    assert shares.loc[("yeo", 3), "toys"] == 2
    table = name_strategy_table(results, 0.4)
    rows = {row[1]: row for row in table.rows}
    assert [row[1] for row in table.rows[:2]] == ["iuo", "yeo"]  # said most often first
    assert rows["iuo"][2:] == ["1", "100%", "50%", "n/a", "100%", "0% / 0% / 100%"]
    assert rows["yeo"][3] == "50%"
    # Said: iuo (A) and yeo (B); never said: yeo (A).
    assert rows["names never said"][2:] == ["1", "", "0%", "n/a", "0%", "0% / 100% / 0%"]
    assert rows["names said within the distance"][6] == "67%"
    assert group in {row[0] for row in table.rows}


def test_trials_evaluated_before_the_toy_was_recorded_give_a_note(batches, tmp_path):
    results = _results(batches)
    assert named_tests(results, 0.4) is not None  # this code's evaluation records it
    old = dataclasses.replace(results, vocal=results.vocal.drop(columns="toy"))
    assert named_tests(old, 0.4) is None and name_strategy_table(old, 0.4) is None


@pytest.mark.slow  # over 5 s: make test-slow runs it
def test_the_report_shows_the_table_or_says_why_not(batches, tmp_path):
    page = write_report(
        batches["kinematic"], tmp_path / "new", measures=room_measures(50)
    ).read_text()
    assert "Strategies by the toy&#39;s name" in page or "Strategies by the toy's name" in page
    assert "names said within the distance" in page or "names never said" in page
    # Trials evaluated before the vocal table recorded the toy, as that version wrote them.
    batch = tmp_path / "old"
    shutil.copytree(batches["kinematic"], batch)
    for eval_file in batch.glob(f"*/{EVAL_FILE}"):
        as_evaluated_before_names_had_toys(eval_file.parent)
    page = write_report(batch, tmp_path / "old-report", measures=room_measures(50)).read_text()
    assert "playroom eval" in page and NOT_RECORDED.split(":")[0] in page


@pytest.mark.slow  # over 5 s: make test-slow runs it
def test_the_comparison_splits_both_backends_by_name(batches, tmp_path):
    from experiments.report.comparison import write_comparison

    page = write_comparison(
        batches["kinematic"],
        batches["physical"],
        tmp_path,
        grasp_rate_commands=20,
        measures=room_measures(50),
    ).read_text()
    section = page[page.index("Strategies by the toy") : page.index("<h2>Trials</h2>")]
    for group in ("kinematic", "physical"):
        assert f"<td>{group}</td>" in section
