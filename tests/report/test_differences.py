"""The comparison's tests over trials (experiments/report/differences.py, measures.py) on
hand-made batches whose answers are known: identical groups give a high p, shifted per-trial
values a low one; a pooled test far smaller than the per-trial one is only a second line; a
value fixed by construction is not tested; the interaction of a gap has the sign of the
difference of the gaps; the page's rows say it all."""

from __future__ import annotations

import numpy as np
import pytest
from scipy import stats
from trial_batches import GEOMETRY, batch

from experiments.analysis import trial_values
from experiments.report import differences
from experiments.report.comparison import tests_note as note_on_tests
from experiments.report.measures import registry

SEEDS = list(range(8))
CENTRE = "Strategies (project's tests; tool = the stick moved (the study's rule)), centre"


def _evaluate(a, b) -> dict[str, differences.Evaluated]:
    return {e.measure.name: e for e in differences.evaluate(registry(GEOMETRY), a, b)}


def _row(rows: list[list[str]], label: str) -> int:
    found = [i for i, r in enumerate(rows) if r[0] == label]
    assert len(found) == 1, label
    return found[0]


def test_identical_groups_give_a_high_p_and_shifted_ones_a_low_one():
    values = np.array([0.10, 0.25, 0.18, 0.30, 0.05, 0.22, 0.15, 0.28])
    a = batch("kinematic", SEEDS, competence=values)
    # The same values on other seeds: the same distribution, paired over seeds.
    same = _evaluate(a, batch("physical", SEEDS, competence=values[::-1]))["competence_all"]
    (test,) = same.outcomes
    assert test.test.paired and test.test.n == (8, 8) and test.test.p > 0.9
    noise = np.array([0.01, -0.02, 0.015, 0.0, -0.01, 0.02, -0.005, 0.01])
    shifted = _evaluate(a, batch("physical", SEEDS, competence=values + 0.1 + noise))
    (test,) = shifted["competence_all"].outcomes
    assert test.test.p == pytest.approx(stats.ttest_rel(values, values + 0.1 + noise).pvalue)
    assert test.test.p < 1e-6 and test.test.difference == pytest.approx(-0.1 - noise.mean())
    # Seeds that do not pair: Welch's t on the per-trial values.
    other = _evaluate(a, batch("physical", [10 + s for s in SEEDS], competence=values + 0.1))
    (test,) = other["competence_all"].outcomes
    assert not test.test.paired and test.test.method == "Welch t"


def _tool_batches():
    """Two groups of 8 trials with 2000 tests each near the centre. Their tool shares differ
    from trial to trial far more than between the groups (by 0.025 on average, +0.1 or -0.05
    by seed): pooled over 16000 tests a side the difference looks certain, over 8 trials it
    is not."""
    shares = np.array([0.2, 0.8, 0.3, 0.7, 0.25, 0.75, 0.35, 0.65])
    shift = np.array([0.1, -0.05] * 4)
    tools_a = [(round(2000 * s), 2000 - round(2000 * s)) for s in shares]
    tools_b = [(round(2000 * s), 2000 - round(2000 * s)) for s in shares + shift]
    a = batch("kinematic", SEEDS, tool_tests=tools_a)
    return a, batch("physical", SEEDS, tool_tests=tools_b)


def test_the_per_trial_test_is_primary_where_the_pooled_one_would_be_tiny():
    a, b = _tool_batches()
    evaluated = _evaluate(a, b)
    centre = evaluated["strategies_project_study_centre"]
    tool = next(o for o in centre.outcomes if o.part == "tool")
    per_trial = [trial_values.strategy_shares(s, "competence", "study", 0.0, 0.5) for s in (a, b)]
    expected = stats.ttest_rel(per_trial[0]["tool"], per_trial[1]["tool"]).pvalue
    assert tool.test.p == pytest.approx(expected) and tool.test.p > 0.1
    (pooled,) = centre.pooled
    assert pooled.p < 1e-4 and pooled.what == "tests"
    # The page: the row's p is the per-trial test's; the pooled one is a labelled second line,
    # not counted in Holm's correction.
    rows = differences.rows(list(evaluated.values()), a, b)
    i = _row(rows, CENTRE)
    assert rows[i][3] == "paired t over seeds (8 pairs)"
    assert f"tool p = {expected:.2g}" in rows[i][4] and "tool no" in rows[i][5]
    label, *_, method, p, holm, rank, rank_holm = rows[i + 1]
    assert label == "└ the same, pooled over tests (treats tests as independent)"
    assert method == "χ²" and p == f"p = {pooled.p:.1e}" and holm == "not counted"
    assert rank == rank_holm == ""  # a pooled line has no test beside it either
    summary = differences.tests_summary(list(evaluated.values()))
    assert {t["measure"] for t in summary["pooled"]} >= {"strategies_project_study_centre"}
    assert summary["count"] == sum(1 for t in summary["tests"] if t["p"] is not None)


def test_holm_counts_every_test_of_the_page():
    a, b = _tool_batches()
    evaluated = list(_evaluate(a, b).values())
    outcomes = [o for e in evaluated for o in e.outcomes if np.isfinite(o.test.p)]
    ps = sorted(o.test.p for o in outcomes)
    smallest = min(outcomes, key=lambda o: o.test.p)
    assert smallest.holm_p == pytest.approx(min(1.0, len(ps) * ps[0]))
    assert all(o.holm_p >= o.test.p for o in outcomes)


def test_a_value_fixed_by_construction_is_shown_not_tested():
    tools = [(10, 10)] * 8
    # A backend that pushes nothing: every tool test held the stick, a share of 0 known, not
    # sampled; the physical trials pushed some.
    a = batch("kinematic", SEEDS, tool_tests=tools, pushes=False)
    b = batch("physical", SEEDS, tool_tests=tools, pushed=[2, 5, 3, 4, 6, 1, 2, 3])
    evaluated = _evaluate(a, b)
    pushed = evaluated["tool_tests_only_pushed"]
    assert pushed.outcomes == () and pushed.pooled == ()
    ((part, why),) = pushed.untested
    assert why.startswith("kinematic: its backend pushes nothing")
    rows = differences.rows(list(evaluated.values()), a, b)
    i = _row(rows, pushed.measure.label)
    assert rows[i][1].startswith("0.0%") and rows[i][3].startswith("not tested: kinematic:")
    assert rows[i][4] == "" and rows[i][5] == ""
    assert all(not r[0].startswith("└") for r in rows[i + 1 :])  # no pooled test of it either
    # A backend that declares it but pushed all the same: the declaration does not hold, so
    # the values are tested like any other.
    c = batch("kinematic", SEEDS, tool_tests=tools, pushed=[0, 0, 1, 0, 0, 0, 0, 0], pushes=False)
    (test,) = _evaluate(c, b)["tool_tests_only_pushed"].outcomes
    assert test.test.paired and np.isfinite(test.test.p)


def _words(gap: float, jitter: float) -> tuple[list[float], list[float]]:
    names = [0.2 + jitter, 0.25, 0.3]
    return names, [d + gap for d in names]


def test_the_interaction_compares_the_gaps_and_has_their_sign():
    jitter = [0.0, 0.01, -0.01, 0.02, -0.02, 0.005, 0.015, -0.005]
    # Kinematic names beat distractors by about 0.10, physical by about 0.02.
    wide = [_words(0.1 + j, j) for j in jitter]
    narrow = [_words(0.02 - j / 2, j) for j in jitter]
    a, b = batch("kinematic", SEEDS, words=wide), batch("physical", SEEDS, words=narrow)
    gap = _evaluate(a, b)["names_vs_distractors"]
    by_part = {o.part: o for o in gap.outcomes}
    assert set(by_part) == {"kinematic", "physical", "interaction"}
    assert by_part["kinematic"].test.statistic > 0 and by_part["kinematic"].test.p < 1e-6
    interaction = by_part["interaction"].test
    assert interaction.statistic > 0 and interaction.difference > 0 and interaction.p < 1e-4
    # The other way round, the other sign.
    back = {o.part: o for o in _evaluate(b, a)["names_vs_distractors"].outcomes}
    assert back["interaction"].test.statistic == pytest.approx(-interaction.statistic)
    rows = differences.rows(list(_evaluate(a, b).values()), a, b)
    i = _row(rows, f"{gap.measure.label}, against 0")
    assert rows[i + 1][0].startswith("└ the names' gap")
    assert rows[i + 1][0].endswith(": kinematic vs physical (interaction)")
    assert rows[i + 1][4] == f"p = {interaction.p:.1e}"
    # The study's pooled Mann-Whitney per group, on the third line, not counted.
    assert rows[i + 2][0].startswith("└ the same, pooled over words") and rows[i + 2][5] == (
        "not counted"
    )
    # The page's sentence: every test counted (the gaps' against 0 too), paired over seeds.
    evaluated = list(_evaluate(a, b).values())
    count = differences.tests_summary(evaluated)["count"]
    assert count == sum(np.isfinite(o.test.p) for e in evaluated for o in e.outcomes) >= 3
    assert note_on_tests(evaluated).startswith(
        f"This table makes {count} tests on per-trial values, paired over seeds"
    )


def test_no_p_on_the_page_is_zero():
    values = np.linspace(0.1, 0.3, 64)
    rng = np.random.default_rng(1)
    a = batch("kinematic", list(range(64)), competence=values)
    b = batch("physical", list(range(64)), competence=values - 1 + 1e-9 * rng.standard_normal(64))
    evaluated = list(_evaluate(a, b).values())
    (test,) = evaluated[0].outcomes
    assert test.test.p == 0.0  # underflowed
    rows = differences.rows(evaluated, a, b)
    assert rows[0][4] == "p < 1e-300"
    assert not any("p = 0" in cell and "p = 0." not in cell for row in rows for cell in row)


def test_summary_holds_each_trials_values_with_its_seed():
    a, b = _tool_batches()
    merged = a.merge(b)
    values = differences.per_trial_values(registry(GEOMETRY), merged)
    centre = values["strategies_project_study_centre"]
    assert centre["parts"] == ["hand", "tool", "vocal"] and centre["kind"] == "share"
    columns = centre["per_trial"]
    assert columns["group"] == ["kinematic"] * 8 + ["physical"] * 8
    assert columns["seed"] == SEEDS + SEEDS
    assert columns["tool"][0] == pytest.approx(0.2) and columns["tool"][9] == pytest.approx(0.75)
