"""What a side's values of a measure rest on, shown beside them on the comparison's table
(`Measure.note`, experiments/report/measures.py): the counts of tests, words or iterations
behind each trial's share, and the errors a share's tests left. Text only: no test here."""

from __future__ import annotations

import numpy as np

from experiments.analysis.results import BatchResults
from experiments.analysis.strategies import MOVERS, trial_shares
from experiments.analysis.trial_values import ACTORS, expectation_tests, ring_tests
from experiments.report.pages import num


def tests_in(side: BatchResults, attribute: str, low: float, high: float) -> str:
    """How many tests of `attribute` ("competence", "study_tests") lie in [low, high)."""
    shares = trial_shares(getattr(side, attribute), low, high, "study")
    return f"{int(shares['n_tests'].sum())} tests" if not shares.empty else ""


def words(side: BatchResults) -> str:
    return f"{len(side.vocal)} words"


def held_or_pushed(side: BatchResults) -> str:
    """The pooled tool tests that held the stick and those that only pushed it."""
    tests = side.competence
    if "stick_grasped" not in tests.columns:
        return ""
    tools = tests[tests["strategy"] == "tool"]
    held = int(tools["stick_grasped"].astype(bool).sum())
    return f"tool tests held / only pushed: {held} / {len(tools) - held}"


def small_tool_uses(side: BatchResults, min_motion: float) -> str:
    tests = side.study_tests
    if tests.empty or "stick_dx" not in tests.columns or tests["stick_dx"].isna().any():
        return ""
    dx = tests.loc[tests["strategy"] == "tool", "stick_dx"].abs()
    return f"{int((dx < min_motion).sum())} of {len(dx)} tool uses"


def study_tests(side: BatchResults) -> str:
    return f"{len(side.study_tests)} tests"


def diverged(side: BatchResults) -> str:
    trials = side.trials
    return f"{int(trials['diverged'].sum())} of {int(trials['iterations'].sum())} iterations"


def errors_left(side: BatchResults, ring: int, actor: str) -> str:
    """The mean error each mover's tests left (pooled over the side's tests)."""
    tests = ring_tests(side, ring)
    if tests is None:
        return ""
    column, error = ACTORS[actor]
    means = tests.groupby(column)[error].mean()
    shown = [f"{m} {num(float(means[m]))}" for m in MOVERS if m in means.index]
    return f"{len(tests)} tests; mean error left: {', '.join(shown)}"


def expected_and_left(side: BatchResults, ring: int) -> str:
    """The error the side's tests expected from memory and the error they left, pooled."""
    tests = expectation_tests(side, ring)
    if tests.empty:
        return ""
    expected = float(np.mean(tests["arm_nn_distance"]))
    left = float(np.mean(tests["error"]))
    return f"{len(tests)} tests: expected {num(expected)}, left {num(left)}"
