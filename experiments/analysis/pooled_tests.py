"""Tests on counts or values pooled over the trials' tests, words or iterations: the tests the
comparison page showed alone before, now only a labelled second line beside the
per-trial test (experiments/analysis/trial_tests.py). They treat every test (word, iteration)
as independent, which the tests of one agent are not: their p is smaller than the batch
supports, the more so the more tests each trial holds.

Each takes the two sides (one group each) and returns `PooledTest`s, none where the tables do
not record what it pools.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import pandas as pd
from scipy import stats

from experiments.analysis.results import BatchResults
from experiments.analysis.stats import STRATEGIES, TOOL_MIN_MOTION, chi_square, mann_whitney, welch
from experiments.analysis.strategies import MOVERS, trial_shares
from experiments.analysis.trial_tests import PooledTest
from experiments.analysis.trial_values import (
    ACTORS,
    WORDS,
    expectation_tests,
    ring_tests,
)

CHI_SQUARE = "χ²"
FISHER = "Fisher exact"
# The study's convention (experiments/analysis/stats.py `mann_whitney`): one-sided p doubled.
MANN_WHITNEY = "Mann-Whitney U (one-sided p doubled, as the study)"


def _chi_square(table: np.ndarray, what: str) -> list[PooledTest]:
    statistic, p = chi_square(table)
    return [PooledTest(CHI_SQUARE, statistic, p, what)]


def strategies(
    a: BatchResults, b: BatchResults, attribute: str, definition: str, low: float, high: float
) -> list[PooledTest]:
    """χ² of sides × strategies on the pooled counts of tests in [low, high)."""
    counts = []
    for side in (a, b):
        shares = trial_shares(getattr(side, attribute), low, high, definition)
        if shares.empty:
            return []
        counts.append([float((shares[s] * shares["n_tests"]).sum()) for s in STRATEGIES])
    return _chi_square(np.round(np.array(counts)), "tests")


def words_within(a: BatchResults, b: BatchResults, threshold: float) -> list[PooledTest]:
    """Fisher's exact test of sides × (within, beyond) on the pooled words."""
    below = [int((s.vocal["best_distance"] < threshold).sum()) for s in (a, b)]
    total = [len(s.vocal) for s in (a, b)]
    if min(total) == 0:
        return []
    table = np.array([[below[0], total[0] - below[0]], [below[1], total[1] - below[1]]])
    result = stats.fisher_exact(table)
    return [PooledTest(FISHER, float(result.statistic), float(result.pvalue), "words")]


def word_distances(a: BatchResults, b: BatchResults, which: str) -> list[PooledTest]:
    """Mann-Whitney U of the two sides' pooled best distances of the words of `which`."""
    values = [s.vocal[WORDS[which](s.vocal)]["best_distance"].to_numpy(float) for s in (a, b)]
    if min(len(v) for v in values) == 0:
        return []
    u, p = mann_whitney(*values)
    return [PooledTest(MANN_WHITNEY, u, p, "words")]


def names_vs_distractors(side: BatchResults) -> PooledTest:
    """Mann-Whitney U of one side's pooled names against its pooled distractors (the study's
    test, on every word of every trial)."""
    vocal = side.vocal
    names = vocal.loc[WORDS["toy names"](vocal), "best_distance"].to_numpy(float)
    distractors = vocal.loc[WORDS["distractors"](vocal), "best_distance"].to_numpy(float)
    u, p = mann_whitney(names, distractors)
    return PooledTest(MANN_WHITNEY, u, p, "words")


def tool_contacts(a: BatchResults, b: BatchResults) -> list[PooledTest]:
    """χ² of sides × (stick held, only pushed) on the pooled tool tests."""
    counts = []
    for side in (a, b):
        tests = side.competence
        if "stick_grasped" not in tests.columns:
            return []
        tools = tests[tests["strategy"] == "tool"]
        held = int(tools["stick_grasped"].astype(bool).sum())
        counts.append([held, len(tools) - held])
    return _chi_square(np.array(counts), "tests")


def _stick_dx(side: BatchResults):
    tests = side.study_tests
    if tests.empty or "stick_dx" not in tests.columns or tests["stick_dx"].isna().any():
        return None
    return tests


def _study_test_counts(
    a: BatchResults, b: BatchResults, count: Callable[[pd.DataFrame], list[int]]
) -> list[PooledTest]:
    """χ² of sides × the two counts `count` makes of each side's study tests (with stick_dx);
    none where a side lacks them."""
    counts = []
    for side in (a, b):
        tests = _stick_dx(side)
        if tests is None:
            return []
        counts.append(count(tests))
    return _chi_square(np.array(counts), "tests")


def small_tool_uses(
    a: BatchResults, b: BatchResults, min_motion: float = TOOL_MIN_MOTION
) -> list[PooledTest]:
    """χ² of sides × (below, at least `min_motion`) on the pooled tool uses of study tests."""

    def count(tests: pd.DataFrame) -> list[int]:
        dx = tests.loc[tests["strategy"] == "tool", "stick_dx"].abs()
        return [int((dx < min_motion).sum()), int((dx >= min_motion).sum())]

    return _study_test_counts(a, b, count)


def tool_share_min_motion(
    a: BatchResults, b: BatchResults, min_motion: float = TOOL_MIN_MOTION
) -> list[PooledTest]:
    """χ² of sides × (tool with at least `min_motion`, other) on the pooled study tests."""

    def count(tests: pd.DataFrame) -> list[int]:
        kept = int(((tests["strategy"] == "tool") & (tests["stick_dx"].abs() >= min_motion)).sum())
        return [kept, len(tests) - kept]

    return _study_test_counts(a, b, count)


def diverged(a: BatchResults, b: BatchResults) -> list[PooledTest]:
    """χ² of sides × (diverged, not) on the pooled iterations."""
    counts = [
        [
            int(s.trials["diverged"].sum()),
            int((s.trials["iterations"] - s.trials["diverged"]).sum()),
        ]
        for s in (a, b)
    ]
    return _chi_square(np.array(counts), "iterations")


def ring_movers(a: BatchResults, b: BatchResults, ring: int, actor: str) -> list[PooledTest]:
    """χ² of sides × movers of the goal toy on the pooled ring-`ring` tests of `actor`."""
    counts = []
    for side in (a, b):
        tests = ring_tests(side, ring)
        if tests is None:
            return []
        found = tests[ACTORS[actor][0]].value_counts()
        counts.append([int(found.get(mover, 0)) for mover in MOVERS])
    return _chi_square(np.array(counts), "tests")


def expectation_gaps(a: BatchResults, b: BatchResults, ring: int) -> list[PooledTest]:
    """Welch's t test of the pooled tests' gaps (error left minus error expected)."""
    gaps = []
    for side in (a, b):
        tests = expectation_tests(side, ring)
        if tests.empty:
            return []
        gaps.append((tests["error"] - tests["arm_nn_distance"]).to_numpy(float))
    t, p = welch(*gaps)
    return [PooledTest("Welch t", t, p, "tests")]
