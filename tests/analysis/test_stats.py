"""The report's statistics on hand-made tables (experiments/analysis/stats.py): each checked
against a value worked out by hand or from the textbook formula."""

from __future__ import annotations

import math

import numpy as np
import pandas as pd
import pytest

from experiments.analysis.stats import (
    chi_square,
    mann_whitney,
    mean_ci,
    strategy_table,
    vocal_summary,
    welch,
)


def test_mean_ci_is_the_student_t_interval():
    # mean 3, s^2 = 2.5, se = sqrt(2.5 / 5) = 0.70711, t(0.975, df 4) = 2.77645
    mean, low, high = mean_ci(np.array([1.0, 2.0, 3.0, 4.0, 5.0]))
    assert mean == 3.0
    assert low == pytest.approx(3 - 2.776445 * 0.7071068, abs=1e-6)
    assert high == pytest.approx(3 + 2.776445 * 0.7071068, abs=1e-6)
    assert math.isnan(mean_ci(np.array([0.4]))[1])


def test_mann_whitney_and_welch_on_known_cases():
    # Every a below every b: U = 0; exact two-sided p = 2 / C(6, 3) = 0.1.
    u, p = mann_whitney(np.array([1.0, 2.0, 3.0]), np.array([4.0, 5.0, 6.0]))
    assert u == 0.0 and p == pytest.approx(0.1)
    # Welch: t = (2 - 5) / sqrt(1/3 + 1/3) = -3.6742, df = 4.
    t, p = welch(np.array([1.0, 2.0, 3.0]), np.array([4.0, 5.0, 6.0]))
    assert t == pytest.approx(-3.674235, abs=1e-5)
    assert p == pytest.approx(0.021311, abs=1e-5)
    assert math.isnan(welch(np.array([1.0]), np.array([2.0, 3.0]))[1])


def test_chi_square_ignores_empty_columns():
    # [[10, 5], [5, 10]]: expected 7.5 everywhere, Yates |O - E| - 0.5 = 2: chi2 = 4 * 4 / 7.5.
    chi2, p = chi_square(np.array([[10, 0, 5], [5, 0, 10]]))
    assert chi2 == pytest.approx(16 / 7.5)
    # One degree of freedom: P(chi2_1 > x) = erfc(sqrt(x / 2)).
    assert p == pytest.approx(math.erfc(math.sqrt(16 / 7.5 / 2)))
    assert math.isnan(chi_square(np.array([[3, 0, 0], [4, 0, 0]]))[1])


def test_vocal_summary_counts_shares_and_medians():
    vocal = pd.DataFrame(
        {
            "is_name": [True, True, True, False, False, False],
            "best_distance": [0.1, 0.2, 0.3, 0.5, 0.6, 0.35],
        }
    )
    summary = vocal_summary(vocal, threshold=0.4)
    assert summary["share_below"] == pytest.approx(4 / 6)
    assert summary["median_names"] == pytest.approx(0.2)
    assert summary["median_distractors"] == pytest.approx(0.5)
    assert summary["u"] == 0.0 and summary["p"] == pytest.approx(0.1)


def test_strategy_table_shares_per_region():
    competence = pd.DataFrame(
        {
            "group": "g",
            "distance": [0.1, 0.2, 0.3, 0.4, 0.6, 0.7, 0.96, 0.99],
            "strategy": ["hand", "hand", "hand", "tool", "vocal", "hand", "vocal", "vocal"],
        }
    )
    table = strategy_table(competence, hand_limit=0.5, stick_limit=0.75).set_index("region")
    assert table.loc["centre", ["hand", "tool", "vocal"]].tolist() == [0.75, 0.25, 0.0]
    assert table.loc["between limits", ["hand", "vocal"]].tolist() == [0.5, 0.5]
    assert table.loc["distance 1", "vocal"] == 1.0 and table.loc["distance 1", "n"] == 2
