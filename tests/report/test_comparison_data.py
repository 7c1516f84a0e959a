"""The comparison's table of differences (experiments/report/differences.py, comparison.py) on
hand-made batches whose answers are known: a nonparametric p beside every t (the signed-rank
test where paired or against 0, Mann-Whitney where the sides do not pair), each kind
Holm-adjusted over the same tests, the verdicts the two disagree on named, and every test
computed again from the per-trial data written beside the page (comparison-trials.csv,
experiments/report/comparison_data.py) alone."""

from __future__ import annotations

import io

import numpy as np
import pytest
from scipy import stats
from trial_batches import GEOMETRY, batch
from trial_recompute import check_tests_again

from experiments.report import comparison_data, differences
from experiments.report.comparison import disagreement_lines
from experiments.report.comparison import tests_note as note_on_tests
from experiments.report.measures import registry
from experiments.report.pages import p_value, pct
from experiments.report.trial_data import read_trial_data

SEEDS = list(range(8))
COMPETENCE = np.array([0.10, 0.25, 0.18, 0.30, 0.05, 0.22, 0.15, 0.28])
NOISE = np.array([0.01, -0.02, 0.015, 0.0, -0.01, 0.02, -0.005, 0.01])


def _words(gap: float, jitter: float) -> tuple[list[float], list[float]]:
    names = [0.2 + jitter, 0.35, 0.5 - jitter]
    return names, [d + gap for d in names]


def _sides(seeds_b: list[int]):
    """Two groups of 8 trials: competence, tool and hand tests near the centre, and words;
    the physical side on `seeds_b` (SEEDS: they pair)."""
    shares = [0.2, 0.8, 0.3, 0.7, 0.25, 0.75, 0.35, 0.65]
    tools = [(round(100 * s), 100 - round(100 * s)) for s in shares]
    a = batch(
        "kinematic",
        SEEDS,
        competence=COMPETENCE,
        tool_tests=tools,
        words=[_words(0.1 + 0.01 * k, 0.01 * k) for k in range(8)],
    )
    b = batch(
        "physical",
        seeds_b,
        competence=COMPETENCE + 0.05 + NOISE,
        tool_tests=tools[::-1],
        words=[_words(0.02 + 0.013 * k, -0.01 * k) for k in range(8)],
        pushed=[1, 0, 2, 0, 1, 3, 0, 1],
    )
    return a, b


def _evaluate(a, b) -> list[differences.Evaluated]:
    return differences.evaluate(registry(GEOMETRY), a, b)


def test_every_t_of_the_table_has_its_nonparametric_p_beside_it():
    a, b = _sides(SEEDS)
    evaluated = _evaluate(a, b)
    rows = differences.rows(evaluated, a, b)
    assert all(len(r) == 8 for r in rows)
    # Every row whose test is a t has as many nonparametric ps beside it as it has ps.
    tested = [r for r in rows if " t " in f" {r[3]} "]
    assert len(tested) >= 5
    for r in tested:
        assert r[6].startswith("Wilcoxon signed-rank ") and r[6].count("p ") == r[4].count("p ")
    competence = next(r for r in rows if r[0] == "Normalised competence, all rings")
    d = COMPETENCE - (COMPETENCE + 0.05 + NOISE)
    expected = stats.wilcoxon(d, zero_method="pratt").pvalue
    assert competence[6] == f"Wilcoxon signed-rank over seeds: {p_value(expected)}"
    assert competence[7] in ("survives", "no")
    gap = next(r for r in rows if r[0].startswith("Names vs distractors") and "against 0" in r[0])
    assert gap[6].startswith("Wilcoxon signed-rank against 0: kinematic p = ")
    # Where the seeds do not pair: the Mann-Whitney U test of the same values, two-sided.
    a, b = _sides([10 + s for s in SEEDS])
    rows = differences.rows(_evaluate(a, b), a, b)
    competence = next(r for r in rows if r[0] == "Normalised competence, all rings")
    expected = stats.mannwhitneyu(COMPETENCE, COMPETENCE + 0.05 + NOISE).pvalue
    assert competence[6] == f"Mann-Whitney U: {p_value(expected)}"


def test_a_verdict_the_two_tests_disagree_on_is_named():
    """Five seeds: the signed-rank test's smallest p is 2 / 2^5 = 0.0625, so Holm keeps none of
    them, while the t keeps a shift every seed shows."""
    seeds = SEEDS[:5]
    a = batch("kinematic", seeds, competence=COMPETENCE[:5])
    b = batch("physical", seeds, competence=COMPETENCE[:5] + 0.1 + 0.1 * NOISE[:5])
    evaluated = _evaluate(a, b)
    (outcome,) = evaluated[0].outcomes
    assert outcome.survives and not outcome.rank_survives
    (line,) = disagreement_lines(evaluated)
    assert line.startswith("Normalised competence, all rings: survives Holm with the t only ")
    assert "Wilcoxon signed-rank over seeds p = 0.062" in line
    note = note_on_tests(evaluated)
    assert "1 of them survive Holm's correction" in note
    assert "the Wilcoxon signed-rank test of the same differences" in note and ": 0 survive" in note
    a, b = _sides(SEEDS)
    evaluated = _evaluate(a, b)
    assert len(disagreement_lines(evaluated)) == sum(
        o.survives != o.rank_survives for e in evaluated for o in e.outcomes
    )


@pytest.mark.parametrize("seeds_b", [SEEDS, [10 + s for s in SEEDS]], ids=["paired", "unpaired"])
def test_every_test_is_computed_again_from_the_per_trial_data_alone(seeds_b):
    """comparison-trials.csv holds all a reader needs: each test of the table (the t's p, the
    nonparametric p, both Holm adjustments, the difference) and each side's mean, computed
    from it with scipy alone, are the page's (summary.json's `trial_tests`, the table's
    cells)."""
    a, b = _sides(seeds_b)
    evaluated = _evaluate(a, b)
    table = comparison_data.trial_table(evaluated, a, b)
    trials = read_trial_data(io.BytesIO(table.to_csv(index=False).encode()))
    assert list(trials.columns[:5]) == ["batch", "group", "seed", "trial", "grasp"]
    assert list(trials.columns[-4:]) == [
        "computed_on",
        "computed_commit",
        "evaluated_on",
        "evaluated_commit",
    ]
    assert {"competence_all", "strategies_project_study_centre:tool"} <= set(trials.columns)
    assert len(trials) == 16 and list(trials["seed"][8:]) == seeds_b
    summary = differences.tests_summary(evaluated)
    assert len(summary["tests"]) >= 8
    assert {t["paired"] for t in summary["tests"] if len(t["n"]) == 2} == {seeds_b == SEEDS}
    check_tests_again(trials, summary["tests"])
    rows = differences.rows(evaluated, a, b)
    competence = next(r for r in rows if r[0] == "Normalised competence, all rings")
    means = trials.groupby("group")["competence_all"].mean()
    assert competence[1].startswith(pct(means["kinematic"], 1) + " [")
    assert competence[2].startswith(pct(means["physical"], 1) + " [")


@pytest.mark.parametrize("commit", ["6163356", "1234e56", "0123456"])
def test_commits_of_digits_alone_read_back_as_the_commits_they_are(commit):
    """A short commit can be all digits, or digits around one 'e': read back from a per-trial
    data file whose trials one such commit computed, it stays the text it was, not a number
    (the bug commit 6163356 showed)."""
    a, b = _sides(SEEDS)
    table = comparison_data.trial_table(_evaluate(a, b), a, b)
    table["computed_commit"] = table["evaluated_commit"] = commit
    trials = read_trial_data(io.BytesIO(table.to_csv(index=False).encode()))
    assert trials["computed_commit"].eq(commit).all()
    assert trials["evaluated_commit"].eq(commit).all()
