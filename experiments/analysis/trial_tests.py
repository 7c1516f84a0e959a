"""Tests of differences with the trial, not the test or the word, as the unit.

The agents of a batch share their placements, and each is tested hundreds of times: tests
(and words) of one trial are not independent of each other, so a test that counts them as
independent (χ² or Fisher on pooled counts) reports a certainty the batch does not hold. Every
difference is therefore tested on one value per trial:
- `difference_test`: two groups. Paired over seeds (Student's t on the per-seed differences,
  `scipy.stats.ttest_rel`) where both groups hold the same seeds, since a seed fixes the
  placements and the first random draws of both agents; Welch's t otherwise. Beside the t, a
  nonparametric p on the same values (`rank_method`, `rank_p`): Wilcoxon's signed-rank test of
  the per-seed differences where paired, the Mann-Whitney U test (stats.mann_whitney) where not.
- `one_sample_test`: one group's per-trial values against 0 (e.g. each trial's gap between
  its distractors and its names), with the signed-rank test of the values against 0 beside it.
- `signed_rank_p`: the Wilcoxon signed-rank test's p of paired differences, shown beside every
  paired t where the pages give a nonparametric p (experiments/analysis/step_split.py).
- `holm`: Holm's step-down adjustment of a page's p-values for the number of tests it makes
  (scipy's `false_discovery_control` is Benjamini-Hochberg, a false discovery rate, not the
  family-wise error Holm bounds).
A pooled test is kept only as a labelled second line beside the per-trial one (`PooledTest`).

Values that are not finite (a word never approached: an infinite distance) are left out of a
test, and the n it reports counts the values it used. Every p is two-sided; NaN where no test
can be made (fewer than two values a side, or no variance at all).
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Literal

import numpy as np
import pandas as pd
from scipy import stats

from experiments.analysis.stats import mann_whitney, welch

# The family-wise error rate Holm's correction holds the page's tests to.
ALPHA = 0.05
PAIRED = "paired t over seeds"
WELCH = "Welch t"
ONE_SAMPLE = "one-sample t against 0"
# The nonparametric test beside each t above, in the same order.
SIGNED_RANK = "Wilcoxon signed-rank over seeds"
MANN_WHITNEY = "Mann-Whitney U"
SIGNED_RANK_ZERO = "Wilcoxon signed-rank against 0"


@dataclass(frozen=True)
class TrialTest:
    """A test on per-trial values. `statistic` is t of the first group minus the second (or of
    the values against 0); `n` the values used per group (pairs: the number of pairs, twice);
    `difference` the mean difference (paired), difference of means (Welch) or mean (one
    sample); `rank_p` the two-sided p of the nonparametric test `rank_method` on the same
    values, NaN wherever the t has no p (so that both kinds of p count the same tests)."""

    method: str
    statistic: float
    p: float
    n: tuple[int, ...]
    paired: bool
    difference: float
    rank_method: str
    rank_p: float


@dataclass(frozen=True)
class PooledTest:
    """A test on counts or values pooled over the trials' tests or words: shown only as a
    second line beside a per-trial test, and never counted in the page's correction."""

    method: str
    statistic: float
    p: float
    what: str  # what it pools ("tests", "words", "iterations"), said on its line


def _finite(values: np.ndarray) -> np.ndarray:
    array = np.asarray(values, dtype=float)
    return array[np.isfinite(array)]


def seeds_pair(a: Sequence[int], b: Sequence[int]) -> bool:
    """Whether two groups' trials pair by seed: each holds every seed once and both hold the
    same seeds, at least two of them."""
    return len(a) >= 2 and len(set(a)) == len(a) == len(b) == len(set(b)) and set(a) == set(b)


def _constant(values: np.ndarray) -> bool:
    return bool(np.all(values == values[0]))


def paired_arrays(a: pd.Series, b: pd.Series) -> tuple[np.ndarray, np.ndarray]:
    """The values of the seeds both series hold (indexed by seed), in seed order, pairs with a
    non-finite value on either side left out."""
    common = sorted(set(a.index) & set(b.index))
    x = a.loc[common].to_numpy(dtype=float)
    y = b.loc[common].to_numpy(dtype=float)
    keep = np.isfinite(x) & np.isfinite(y)
    return x[keep], y[keep]


def difference_test(a: pd.Series, b: pd.Series, paired: bool) -> TrialTest:
    """Group `a` against group `b`, their per-trial values indexed by seed: the paired t test
    over the seeds both hold (`paired`), or Welch's t test on all finite values."""
    if paired:
        x, y = paired_arrays(a, b)
        d = x - y
        mean = float(d.mean()) if len(d) else math.nan
        n = (len(d), len(d))
        if len(d) < 2 or _constant(d):
            return TrialTest(PAIRED, math.nan, math.nan, n, True, mean, SIGNED_RANK, math.nan)
        result = stats.ttest_rel(x, y)
        t, p = float(result.statistic), float(result.pvalue)
        return TrialTest(PAIRED, t, p, n, True, mean, SIGNED_RANK, signed_rank_p(d))
    x, y = _finite(a.to_numpy()), _finite(b.to_numpy())
    mean = float(x.mean() - y.mean()) if len(x) and len(y) else math.nan
    t, p = welch(x, y)
    rank = mann_whitney(x, y)[1] if math.isfinite(p) else math.nan
    return TrialTest(WELCH, t, p, (len(x), len(y)), False, mean, MANN_WHITNEY, rank)


def one_sample_test(values: pd.Series) -> TrialTest:
    """One group's per-trial values against 0 (Student's t)."""
    x = _finite(values.to_numpy())
    mean = float(x.mean()) if len(x) else math.nan
    if len(x) < 2 or _constant(x):
        return TrialTest(
            ONE_SAMPLE, math.nan, math.nan, (len(x),), False, mean, SIGNED_RANK_ZERO, math.nan
        )
    with warnings.catch_warnings():
        # Nearly constant values: scipy warns of precision loss; the test is still reported.
        warnings.simplefilter("ignore", RuntimeWarning)
        result = stats.ttest_1samp(x, 0.0)
    t, p = float(result.statistic), float(result.pvalue)
    return TrialTest(ONE_SAMPLE, t, p, (len(x),), False, mean, SIGNED_RANK_ZERO, signed_rank_p(x))


# Why Wilcoxon's signed-rank test and not a sign-flip permutation of the seeds
# (scipy.stats.permutation_test): on the pages' 32 pairs its p is exact (every one of the 2^32
# sign patterns of the ranks counted, scipy's method "auto" for n <= 50 without ties or zero
# differences), deterministic, and reaches down to 2^-31; a Monte Carlo sign flip's p cannot go
# below 1 / (resamples + 1), 1e-4 with scipy's default 9999, while the smallest p of a family of
# 220 tests needs 0.05 / 220 = 2.3e-4 to survive Holm, and an exact sign flip of the mean over
# 2^32 patterns is out of reach. In a simulation outside the project (2026-11, data consistent
# with the contact ladder's page), over 32 seeds both agreed with the t on nearly every star with
# p <= 1e-4. With ties or zero differences (a measure of few values,
# words within 0.4) scipy uses the normal approximation, the zero differences ranked and their
# ranks then dropped ("pratt": a pair that did not change still lifts the others' ranks, rather
# than being discarded as if the seed had not been run).
ZERO_METHOD: Literal["pratt"] = "pratt"


def signed_rank_p(differences: np.ndarray) -> float:
    """Two-sided p of Wilcoxon's signed-rank test that paired differences are symmetric about 0;
    NaN below two finite differences or when they are all equal (no test, as for the t)."""
    d = _finite(differences)
    if len(d) < 2 or _constant(d):
        return math.nan
    with warnings.catch_warnings():
        # scipy warns that the exact p is not available with ties or zeros: it then uses the
        # normal approximation, which is the p intended (ZERO_METHOD's comment).
        warnings.simplefilter("ignore", UserWarning)
        result = stats.wilcoxon(d, zero_method=ZERO_METHOD)
    return float(result.pvalue)


def holm(p: Sequence[float]) -> np.ndarray:
    """Holm's adjusted p-values, in the order given: sorted ascending, the k-th smallest of m
    is multiplied by m - k + 1 (k from 1), capped at 1, and each kept at least as large as
    the one before it. NaN (no test) stays NaN and does not count in m."""
    values = np.asarray(p, dtype=float)
    out = np.full(values.shape, math.nan)
    tested = np.flatnonzero(np.isfinite(values))
    m = len(tested)
    running = 0.0
    for rank, i in enumerate(tested[np.argsort(values[tested], kind="stable")]):
        running = max(running, min(1.0, (m - rank) * values[i]))
        out[i] = running
    return out


def survives(adjusted: float, alpha: float = ALPHA) -> bool:
    """Whether a Holm-adjusted p rejects at `alpha`."""
    return bool(np.isfinite(adjusted) and adjusted <= alpha)
