"""What the logs and the tests say of why two sides differ: the numbers from a log,
the strategy shares under both definitions of "tool", and ring 1's outcomes, on tables whose
answers are known by construction."""

from __future__ import annotations

import math

import numpy as np
import pandas as pd
import pytest

from experiments.analysis.mechanisms import LABELS, LOG_COLUMNS, trial_mechanisms
from experiments.analysis.strategies import held_strategy, share_intervals
from experiments.report.mechanisms import ring_outcomes
from experiments.trial_dir.log_schema import (
    GOAL_COLUMNS,
    REACHED_COLUMNS,
    STICK_MOVED_BY,
    WORD_RECOGNISED,
)

NAMES = {"oey", "uye", "iuo"}
WORDS = NAMES | {"eyu", "eou", "yeo"}
SOUND = {w: np.full(10, i / 10, dtype=np.float32) for i, w in enumerate(sorted(WORDS))}


def _row(iteration: int, model: int, space: str, **values) -> dict:
    row = {c: "" for c in LOG_COLUMNS if c.endswith(("_said", "_recognised", "_moved_by"))}
    row |= {c: np.nan for c in (*GOAL_COLUMNS, *REACHED_COLUMNS)}
    row |= {"iteration": iteration, "model": model, "motor_space": space, "stick_grasped": False}
    for key, value in values.items():
        if key in ("goal", "reached"):
            row |= dict(zip(GOAL_COLUMNS if key == "goal" else REACHED_COLUMNS, value, strict=True))
        else:
            row[key] = value
    return row


@pytest.fixture()
def log() -> pd.DataFrame:
    """10 iterations: a bootstrap movement, arm movements holding toy1 (name "oey" said, heard
    through model 6), one pushing toy2, one taking the stick; model 10 imitating "oey" twice
    and "eyu" once plus one goal of its own; a vocal toy goal understood as a name."""
    rows = [
        _row(0, -1, "arm", caregiver_said="eou"),
        _row(1, 5, "arm", caregiver_said="oey", toy1_moved_by="hand", reached=SOUND["oey"]),
        _row(2, 5, "arm", caregiver_said="eyu", toy2_moved_by="push", reached=SOUND["eyu"]),
        _row(3, 1, "arm", caregiver_said="eyu", stick_grasped=True, stick_moved_by="hand"),
        _row(4, 9, "voice", goal=SOUND["oey"]),
        _row(5, 9, "voice", goal=SOUND["oey"]),
        _row(6, 9, "voice", goal=SOUND["eyu"]),
        _row(7, 9, "voice", goal=np.linspace(-1, 1, 10)),
        _row(8, 6, "voice", word_recognised="oey", toy1_moved_by="caregiver"),
        _row(9, 7, "voice", word_recognised="eyu"),
    ]
    return pd.DataFrame(rows)


def test_a_log_gives_where_exploration_went_and_what_was_heard(log):
    m = trial_mechanisms(log, NAMES, WORDS)
    assert set(m) == set(LABELS)
    assert m["model_share_10"] == pytest.approx(4 / 9)  # the bootstrap is not a goal
    assert m["model_share_7"] == pytest.approx(1 / 9)
    assert m["heard_per_name"] == pytest.approx(1 / 3)  # "oey" once, over 3 names
    assert m["heard_per_distractor"] == pytest.approx(3 / 3)  # eou, eyu, eyu
    assert m["imitation_goals_per_name"] == pytest.approx(2 / 3)
    assert m["imitation_goals_per_distractor"] == pytest.approx(1 / 3)
    assert m["random_sound_goals"] == 1
    assert (m["recognised_names"], m["recognised_distractors"]) == (1, 1)
    assert m["name_recognised_after_toy_goal"] == pytest.approx(1 / 2)  # models 7 and 8
    assert m["first_name_recognised"] == 8
    assert m["toy_held"] == pytest.approx(1000 / 4)
    assert m["toy_pushed"] == pytest.approx(1000 / 4)
    assert m["stick_held"] == pytest.approx(1000 / 4)
    assert m["stick_pushed"] == 0


IMITATION = ("imitation_goals_per_name", "imitation_goals_per_distractor", "random_sound_goals")


@pytest.mark.parametrize(
    "dropped, missing",
    [
        (GOAL_COLUMNS[3], IMITATION),
        (REACHED_COLUMNS[0], IMITATION),
        (STICK_MOVED_BY, ("stick_held", "stick_pushed")),
        (
            WORD_RECOGNISED,
            (
                "recognised_names",
                "recognised_distractors",
                "first_name_recognised",
                "name_recognised_after_toy_goal",
            ),
        ),
    ],
)
def test_a_log_without_a_column_gives_no_number_from_it_and_every_other(log, dropped, missing):
    whole = trial_mechanisms(log, NAMES, WORDS)
    m = trial_mechanisms(log.drop(columns=[dropped]), NAMES, WORDS)
    assert [k for k, v in m.items() if math.isnan(v)] == [k for k in LABELS if k in missing]
    assert {k: v for k, v in m.items() if k not in missing} == {
        k: v for k, v in whole.items() if k not in missing
    }


def test_goals_an_older_trial_did_not_log_give_no_imitation_numbers(log):
    # As read_log reads a trial written before goals and outcomes were logged: NaN throughout.
    older = log.assign(**dict.fromkeys((*GOAL_COLUMNS, *REACHED_COLUMNS), np.float32("nan")))
    m = trial_mechanisms(older, NAMES, WORDS)
    assert [k for k, v in m.items() if math.isnan(v)] == list(IMITATION)


def _tests(strategies: list[str], contacts: list[str], trial: str) -> pd.DataFrame:
    return pd.DataFrame(
        {
            "group": "g",
            "trial": trial,
            "distance": 0.2,
            "strategy": strategies,
            "stick_contact": contacts,
        }
    )


def test_tool_means_held_in_the_second_definition_with_intervals_over_trials():
    tests = pd.concat(
        [
            _tests(
                ["tool", "tool", "hand", "vocal"], ["held", "pushed", "untouched", "untouched"], "a"
            ),
            _tests(
                ["tool", "hand", "hand", "vocal"],
                ["pushed", "untouched", "untouched", "untouched"],
                "b",
            ),
        ]
    )
    assert list(held_strategy(tests)) == [
        "tool",
        "hand",
        "hand",
        "vocal",
        "hand",
        "hand",
        "hand",
        "vocal",
    ]
    regions = {"centre": (0.0, 0.5)}
    study = share_intervals(tests, regions, "study").set_index("strategy")
    held = share_intervals(tests, regions, "held").set_index("strategy")
    assert study.loc["tool", "mean"] == pytest.approx((2 / 4 + 1 / 4) / 2)
    assert held.loc["tool", "mean"] == pytest.approx((1 / 4 + 0) / 2)
    assert held.loc["tool", "count"] == 1 and held.loc["hand", "count"] == 5
    assert held.loc["tool", "low"] < held.loc["tool", "mean"] < held.loc["tool", "high"]
    assert set(held["n_trials"]) == {2} and set(held["n_tests"]) == {8}


def test_ring_outcomes_set_the_agents_movers_against_random_ones_in_the_same_scenes():
    competence = pd.DataFrame(
        {
            "group": "g",
            "ring": [1, 1, 1, 1, 2],
            "goal_moved_by": ["push", "push", "hand", "none", "hand"],
            "random_goal_moved_by": ["none", "none", "none", "hand", "none"],
            "error": [0.5, 0.7, 0.1, 0.3, 9.0],
            "random_error": [0.3, 0.3, 0.3, 0.2, 9.0],
        }
    )
    table = ring_outcomes(competence).set_index(["actor", "mover"])
    assert table.loc[("agent", "push"), "share"] == 0.5
    assert table.loc[("agent", "push"), "mean_error"] == pytest.approx(0.6)
    assert table.loc[("random", "none"), "share"] == 0.75
    assert table.loc[("random", "hand"), "mean_error"] == pytest.approx(0.2)
    # Evaluations before the columns existed: no rows, not a guess.
    assert ring_outcomes(competence.drop(columns=["random_goal_moved_by"])).empty
