"""Tests over trials (experiments/analysis/trial_tests.py): Holm's correction against values
worked out by hand, pairing by seed, the tests against scipy's, and p-values printed with two
significant digits and never as 0."""

from __future__ import annotations

import math

import numpy as np
import pandas as pd
import pytest
from scipy import stats

from experiments.analysis.trial_tests import (
    difference_test,
    holm,
    one_sample_test,
    seeds_pair,
    survives,
)
from experiments.report.pages import p_value


def test_holm_on_a_small_example_worked_by_hand():
    # Sorted: 0.005 x 4 = 0.02; 0.01 x 3 = 0.03; 0.03 x 2 = 0.06; 0.04 x 1 = 0.04, kept at
    # least the 0.06 before it: the step-down never lets a larger p adjust below a smaller.
    adjusted = holm([0.01, 0.04, 0.03, 0.005])
    assert adjusted == pytest.approx([0.03, 0.06, 0.06, 0.02])
    assert [survives(p) for p in adjusted] == [True, False, False, True]
    # A test without a p is no test: it is not counted in m.
    partial = holm([0.01, math.nan, 0.04])
    assert partial[0] == pytest.approx(0.02) and math.isnan(partial[1])
    assert partial[2] == pytest.approx(0.04)
    assert list(holm([0.5, 0.6])) == [1.0, 1.0]  # capped at 1
    assert len(holm([])) == 0


def test_seeds_pair_only_when_both_groups_hold_the_same_seeds_once():
    assert seeds_pair([0, 1, 2], [2, 1, 0])
    assert not seeds_pair([0, 1], [0])
    assert not seeds_pair([0, 1], [0, 2])
    assert not seeds_pair([0, 0], [0, 0])
    assert not seeds_pair([0], [0])  # one pair: no test either way


def _by_seed(values, seeds=None) -> pd.Series:
    return pd.Series(values, index=seeds if seeds is not None else range(len(values)))


def test_the_paired_test_is_scipys_on_the_seeds_both_hold():
    a = _by_seed([1.0, 2.0, 3.0, 5.0, np.inf], [0, 1, 2, 3, 4])
    b = _by_seed([0.0, 2.5, 1.0, 1.0, 9.0], [3, 2, 1, 0, 9])
    test = difference_test(a, b, paired=True)
    x, y = np.array([1.0, 2.0, 3.0, 5.0]), np.array([1.0, 1.0, 2.5, 0.0])  # seeds 0-3
    assert test.p == pytest.approx(stats.ttest_rel(x, y).pvalue)
    assert test.statistic == pytest.approx(stats.ttest_rel(x, y).statistic)
    assert test.n == (4, 4) and test.paired and test.difference == pytest.approx(np.mean(x - y))
    # Welch on all finite values where the seeds do not pair.
    welch = difference_test(a, b, paired=False)
    finite_a = [1.0, 2.0, 3.0, 5.0]
    expected = stats.ttest_ind(finite_a, [0.0, 2.5, 1.0, 1.0, 9.0], equal_var=False).pvalue
    assert welch.p == pytest.approx(expected) and welch.n == (4, 5) and not welch.paired


def test_no_test_without_variance_or_with_one_value():
    same = difference_test(_by_seed([1.0, 2.0]), _by_seed([0.5, 1.5]), paired=True)
    assert math.isnan(same.p) and same.difference == pytest.approx(0.5)
    assert math.isnan(one_sample_test(_by_seed([0.3])).p)
    test = one_sample_test(_by_seed([0.1, 0.3, 0.2, -0.05]))
    assert test.p == pytest.approx(stats.ttest_1samp([0.1, 0.3, 0.2, -0.05], 0.0).pvalue)


@pytest.mark.parametrize(
    "p, text",
    [
        (0.0, "p < 1e-300"),  # underflowed: a bound, never "p = 0"
        (5e-320, "p < 1e-300"),  # a subnormal float: its digits are lost
        (6.6e-256, "p = 6.6e-256"),
        (1.44e-17, "p = 1.4e-17"),
        (0.0625, "p = 0.062"),
        (0.0021, "p = 0.0021"),
        (1.0, "p = 1"),
        (math.nan, "n/a"),
    ],
)
def test_p_values_print_with_two_significant_digits_never_as_zero(p, text):
    assert p_value(p) == text


def test_a_p_that_underflows_prints_as_a_bound():
    # 64 differences of 1 with noise of 1e-9: t is about 1e10, beyond the float range's tail.
    rng = np.random.default_rng(0)
    d = 1.0 + 1e-9 * rng.standard_normal(64)
    test = difference_test(_by_seed(d), _by_seed(np.zeros(64)), paired=True)
    assert test.p == 0.0
    assert p_value(test.p) == "p < 1e-300"


def test_the_signed_rank_p_is_exact_on_few_pairs_and_none_where_every_pair_is_equal():
    from experiments.analysis.trial_tests import signed_rank_p

    # 8 differences of one sign, no ties: the exact two-sided p is 2 / 2^8.
    assert signed_rank_p(np.arange(1.0, 9.0)) == pytest.approx(2 / 2**8)
    assert np.isnan(signed_rank_p(np.zeros(8))) and np.isnan(signed_rank_p(np.full(8, 0.3)))
    assert np.isnan(signed_rank_p(np.array([1.0])))
    # Ties (a measure of few values): the normal approximation, a p all the same.
    assert 0 < signed_rank_p(np.array([0.0, 0.0, 1, 1, 1, 2, 2, -1] * 4)) < 0.05


def test_every_t_has_its_nonparametric_p_on_the_same_values_beside_it():
    """Paired: the signed-rank test of the differences of the seeds both hold; unpaired: the
    Mann-Whitney U test of all finite values (scipy's two-sided p); against 0: the signed-rank
    test of the values; and none where the t has none."""
    a = _by_seed([1.0, 2.0, 3.0, 5.0, 4.5, np.inf], [0, 1, 2, 3, 4, 5])
    b = _by_seed([0.0, 2.5, 1.0, 1.0, 3.0, 9.0], [3, 2, 1, 0, 4, 9])
    paired = difference_test(a, b, paired=True)
    d = np.array([1.0, 2.0, 3.0, 5.0, 4.5]) - np.array([1.0, 1.0, 2.5, 0.0, 3.0])
    assert paired.rank_method == "Wilcoxon signed-rank over seeds"
    assert paired.rank_p == pytest.approx(stats.wilcoxon(d, zero_method="pratt").pvalue)
    unpaired = difference_test(a, b, paired=False)
    expected = stats.mannwhitneyu([1.0, 2.0, 3.0, 5.0, 4.5], [0.0, 2.5, 1.0, 1.0, 3.0, 9.0])
    assert unpaired.rank_method == "Mann-Whitney U"
    assert unpaired.rank_p == pytest.approx(expected.pvalue)
    values = [0.1, 0.3, 0.2, -0.05, 0.4]
    within = one_sample_test(_by_seed(values))
    assert within.rank_method == "Wilcoxon signed-rank against 0"
    assert within.rank_p == pytest.approx(stats.wilcoxon(values).pvalue)
    same = difference_test(_by_seed([1.0, 2.0]), _by_seed([0.5, 1.5]), paired=True)
    assert math.isnan(same.rank_p)
    constant = difference_test(_by_seed([1.0, 1.0]), _by_seed([1.0, 1.0], [5, 6]), paired=False)
    assert math.isnan(constant.p) and math.isnan(constant.rank_p)
