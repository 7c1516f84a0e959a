"""One p-value convention everywhere (the study's: the one-sided Mann-Whitney p doubled)."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest
from scipy import stats

from experiments.analysis.stats import mann_whitney, vocal_summary


def test_the_p_is_the_one_sided_p_doubled_capped_at_1():
    names = np.array([0.10, 0.12, 0.15, 0.20, 0.22, 0.25, 0.31, np.inf])
    distractors = np.array([0.18, 0.24, 0.28, 0.30, 0.35, 0.40, 0.45, 0.50, np.inf])
    one_sided = stats.mannwhitneyu(names, distractors, alternative="less")
    u, p = mann_whitney(names, distractors)
    assert u == one_sided.statistic
    assert p == pytest.approx(2 * one_sided.pvalue) and p < 0.1  # not capped
    # The same words the other way round: the data lean the other way, the same p.
    assert mann_whitney(distractors, names)[1] == pytest.approx(p)
    # No difference: the doubled one-sided p passes 1 and is capped there.
    same = np.array([0.2, 0.3, 0.4])
    assert 2 * stats.mannwhitneyu(same, same, alternative="less").pvalue > 1
    assert mann_whitney(same, same)[1] == 1.0
    # The report's vocal numbers carry that p.
    vocal = {
        "is_name": [True] * len(names) + [False] * len(distractors),
        "best_distance": [*names, *distractors],
    }
    assert vocal_summary(pd.DataFrame(vocal), 0.4)["p"] == pytest.approx(p)
