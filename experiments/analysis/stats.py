"""The report's statistics: pure functions on the tables of `experiments.analysis.results`.

Proportions (competence, strategy shares) are fractions in [0, 1] (competence can be negative:
worse than random); distances are the caregiver's word distances; costs are seconds. Every p
is two-sided; the Mann-Whitney p is the study's: the one-sided p doubled (docs/protocol.md
D24). Functions return NaN rather than raise where a test has too little data, so that a
small batch still gets a report with "n/a" where a number cannot be had.
"""

from __future__ import annotations

import math
import warnings
from typing import Any

import numpy as np
import pandas as pd
from numpy.typing import ArrayLike
from scipy import stats

from experiments.analysis.geometry import Geometry
from experiments.analysis.results import BatchResults
from experiments.analysis.trial_rows import COMPETENCE_SCOPES

STRATEGIES = ("hand", "tool", "vocal")
# Toys at least this far from the arm's base count as "at distance 1" (paper, Fig. 4).
DISTANCE_ONE = 0.95
# The smallest motion of the stick's x (m) that the reports' second count of the study's tool
# uses accepts (`tool_motion`); the study's rule, the primary measure, takes any difference.
# 1 mm is the project's own "moved" (models/layout.py MOVED_DISTANCE: its measure's tool rule,
# the world's events): the |dx| of the study's tool tests has no gap to cut at (the demo batch,
# 4 seeds x 20000 iterations, study preset: physical 41 of 516 tool tests below 1 mm, spread
# from 4e-9 m up, 9 of them below 0.1 mm; kinematic 7 of 493), and below 1 mm the arm did not
# move the stick the way a tool is used, whatever the backend (docs/protocol.md D14).
TOOL_MIN_MOTION = 1e-3


def mean_ci(values: np.ndarray, confidence: float = 0.95) -> tuple[float, float, float]:
    """(mean, low, high) of a 1-D array: Student t interval of the mean over its finite
    values; NaN bounds below 2 finite values, all NaN without any."""
    values = np.asarray(values, dtype=float)
    values = values[np.isfinite(values)]
    if len(values) == 0:
        return math.nan, math.nan, math.nan
    mean = float(values.mean())
    if len(values) < 2:
        return mean, math.nan, math.nan
    half = stats.t.ppf(0.5 + confidence / 2, len(values) - 1) * stats.sem(values)
    return mean, float(mean - half), float(mean + half)


def competence_summary(trials: pd.DataFrame) -> pd.DataFrame:
    """Per group and scope (all, ring1..3): n trials, mean normalised competence, 95% CI.
    `trials`: one row per trial with group and competence_<scope> columns."""
    rows = []
    for group, table in trials.groupby("group", sort=False):
        for scope in COMPETENCE_SCOPES:
            mean, low, high = mean_ci(table[f"competence_{scope}"].to_numpy())
            rows.append(
                {
                    "group": group,
                    "scope": scope,
                    "n": len(table),
                    "mean": mean,
                    "low": low,
                    "high": high,
                }
            )
    return pd.DataFrame(rows, columns=["group", "scope", "n", "mean", "low", "high"])


def regions(hand_limit: float, stick_limit: float) -> dict[str, tuple[float, float]]:
    """The paper's three regions of toy distance for strategy shares (Fig. 4's text):
    name -> [low, high) distance from the arm's base."""
    return {
        "centre": (0.0, hand_limit),
        "between limits": (hand_limit, stick_limit),
        "distance 1": (DISTANCE_ONE, math.inf),
    }


def strategy_counts(
    competence: pd.DataFrame, hand_limit: float, stick_limit: float
) -> pd.DataFrame:
    """Counts of tests per group and region: columns group, region, hand, tool, vocal."""
    rows = []
    for group, table in competence.groupby("group", sort=False):
        for region, (low, high) in regions(hand_limit, stick_limit).items():
            inside = table[(table["distance"] >= low) & (table["distance"] < high)]
            counts = inside["strategy"].value_counts()
            rows.append(
                {"group": group, "region": region} | {s: int(counts.get(s, 0)) for s in STRATEGIES}
            )
    return pd.DataFrame(rows, columns=["group", "region", *STRATEGIES])


def strategy_table(competence: pd.DataFrame, hand_limit: float, stick_limit: float) -> pd.DataFrame:
    """Shares of hand, tool, vocal per group and region (NaN in a region without tests), with
    the number of tests n."""
    counts = strategy_counts(competence, hand_limit, stick_limit)
    n = counts[list(STRATEGIES)].sum(axis=1)
    shares = counts[list(STRATEGIES)].div(n.replace(0, np.nan), axis=0)
    return pd.concat([counts[["group", "region"]], shares, n.rename("n")], axis=1)


def tool_motion(tests: pd.DataFrame, min_motion: float = TOOL_MIN_MOTION) -> pd.DataFrame:
    """Per group of the study's tests (`BatchResults.study_tests`): `tests`; `tool`, the tool
    tests by the study's rule (the stick's x changed at all); `small`, those of them whose
    stick's x moved less than `min_motion` (m); `tool_share` = tool / tests and
    `tool_share_min_motion` = (tool - small) / tests, a test below the minimum counting as the
    hand (arm, stick still). `small` and the second share are NaN in a group with a test
    recorded before `stick_dx` was (its trials evaluated by an older version)."""
    rows = []
    for group, table in tests.groupby("group", sort=False):
        tool = table["strategy"] == "tool"
        recorded = "stick_dx" in table.columns and bool(table["stick_dx"].notna().all())
        small = int((tool & (table["stick_dx"].abs() < min_motion)).sum()) if recorded else math.nan
        n = len(table)
        rows.append(
            {
                "group": group,
                "tests": n,
                "tool": int(tool.sum()),
                "small": small,
                "tool_share": tool.sum() / n,
                "tool_share_min_motion": (tool.sum() - small) / n,
            }
        )
    columns = ["group", "tests", "tool", "small", "tool_share", "tool_share_min_motion"]
    return pd.DataFrame(rows, columns=columns)


def vocal_summary(vocal: pd.DataFrame, threshold: float) -> dict[str, float]:
    """Share of words below the recognition threshold, median best distance of names and
    distractors, and the Mann-Whitney U test of names against distractors (`mann_whitney`:
    two-sided, the one-sided p doubled as the study did).
    `vocal`: one row per word with is_name and best_distance."""
    names = vocal.loc[vocal["is_name"], "best_distance"].to_numpy(dtype=float)
    distractors = vocal.loc[~vocal["is_name"], "best_distance"].to_numpy(dtype=float)
    u, p = mann_whitney(names, distractors)
    return {
        "n_words": len(vocal),
        "share_below": float((vocal["best_distance"] < threshold).mean()),
        "median_names": float(np.median(names)) if len(names) else math.nan,
        "median_distractors": float(np.median(distractors)) if len(distractors) else math.nan,
        "u": u,
        "p": p,
    }


def mann_whitney(a: ArrayLike, b: ArrayLike) -> tuple[float, float]:
    """(U of a, two-sided p); NaN when a side is empty. The p is the study's convention
    (docs/protocol.md D24): the one-sided p in the direction the data lean, doubled and capped
    at 1, which is what the study did with the one-sided p its scipy returned. Infinite values
    (a word never approached) rank above every finite one, which is what they mean."""
    a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    if len(a) == 0 or len(b) == 0:
        return math.nan, math.nan
    less = stats.mannwhitneyu(a, b, alternative="less")
    greater = stats.mannwhitneyu(a, b, alternative="greater")
    # Written out rather than scipy's "two-sided" so that the convention is the code itself.
    p = min(1.0, 2.0 * min(float(less.pvalue), float(greater.pvalue)))
    return float(less.statistic), p


def bias_corrected_interval(
    samples: ArrayLike, estimate: float, confidence: float = 0.95
) -> tuple[float, float] | None:
    """The bias-corrected (BC) bootstrap interval of `estimate` from its bootstrap `samples`:
    z0 = Phi^-1(share of samples below the estimate, ties counted half), then the samples'
    percentiles at Phi(2 z0 -+ z), z = Phi^-1(0.5 + confidence / 2) (Efron 1981). None where
    no honest interval exists: a non-finite estimate or sample, or |z0| > z (the estimate lies
    outside the central `confidence` of its own resamples; the BC interval, like the plain
    percentile one, would then not contain it). As |z0| nears z, one end moves to the most
    extreme resamples, so that end is a bound of the resamples, not of the sampling error.

    Why BC and not BCa: the defect to correct is bias (the study's renormalised shares drop
    in resamples that repeat runs), which z0 measures. BCa's acceleration corrects a standard
    error that changes with the parameter, a smaller, second-order effect; its jackknife over
    runs would be cheap here (n more rows of the resampling product), but a skewness estimated
    from 32-100 leave-one-out values is itself noisy. Why ties count half: the point estimate
    and a resample equal to it are the same sums added in another order, so they differ by
    rounding only."""
    samples = np.asarray(samples, dtype=float).ravel()
    if not math.isfinite(estimate) or len(samples) == 0 or not np.isfinite(samples).all():
        return None
    tied = np.isclose(samples, estimate, rtol=1e-9, atol=1e-12)
    share = (np.sum((samples < estimate) & ~tied) + 0.5 * np.sum(tied)) / len(samples)
    z = float(stats.norm.ppf(0.5 + confidence / 2))
    z0 = float(stats.norm.ppf(share))  # +-inf when every sample lies on one side
    if not abs(z0) <= z:
        return None
    levels = stats.norm.cdf([2 * z0 - z, 2 * z0 + z])
    low, high = (float(q) for q in np.percentile(samples, 100 * levels))
    # The resamples are finitely many, so at |z0| close to z a percentile may step past the
    # estimate: an interval that does not contain its estimate is not given.
    if not low - 1e-12 <= estimate <= high + 1e-12:
        return None
    return low, high


def paired_difference(a: np.ndarray, b: np.ndarray) -> tuple[float, float, float, float]:
    """(mean of a - b, 95% low, high, two-sided p of the paired t test) over pairs a[i], b[i]
    (e.g. two configurations' results on the same seed); NaN below 2 pairs."""
    a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    mean, low, high = mean_ci(a - b)
    if len(a) < 2 or np.all(a - b == (a - b)[0]):
        return mean, low, high, math.nan
    return mean, low, high, float(stats.ttest_rel(a, b).pvalue)


def welch(a: np.ndarray, b: np.ndarray) -> tuple[float, float]:
    """(t, two-sided p) of Welch's t test; NaN below 2 values a side or without variance."""
    a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    if len(a) < 2 or len(b) < 2 or (np.var(a) == 0 and np.var(b) == 0):
        return math.nan, math.nan
    with warnings.catch_warnings():
        # scipy warns of precision loss on nearly constant samples (e.g. 100% vs 99.99% of
        # iterations with the stick in reach); the test is still what the table reports.
        warnings.simplefilter("ignore", RuntimeWarning)
        result = stats.ttest_ind(a, b, equal_var=False)
    return float(result.statistic), float(result.pvalue)


def chi_square(table: np.ndarray) -> tuple[float, float]:
    """(chi2, p) of a contingency table (rows x columns of counts), leaving out all-zero rows
    and columns (they carry no information and make expected counts zero); NaN when fewer
    than 2x2 remain."""
    table = np.asarray(table, dtype=float)
    table = table[table.sum(axis=1) > 0][:, table.sum(axis=0) > 0]
    if table.shape[0] < 2 or table.shape[1] < 2:
        return math.nan, math.nan
    result = stats.chi2_contingency(table)
    return float(result.statistic), float(result.pvalue)


def cost_per_iteration(trials: pd.DataFrame) -> float:
    """Seconds of compute per iteration over the trials that recorded timing.json; NaN if
    none did."""
    timed = trials.dropna(subset=["seconds", "timed_iterations"])
    if timed.empty or timed["timed_iterations"].sum() <= 0:
        return math.nan
    return float(timed["seconds"].sum() / timed["timed_iterations"].sum())


def curve_bands(curves: pd.DataFrame) -> pd.DataFrame:
    """Mean over trials and 95% t interval of each curve metric at each iteration: columns
    group, metric, iteration, mean, low, high, sorted by the first three."""
    rows = []
    for (group, metric, iteration), table in curves.groupby(
        ["group", "metric", "iteration"], sort=False
    ):
        mean, low, high = mean_ci(table["value"].to_numpy())
        rows.append(
            {
                "group": group,
                "metric": metric,
                "iteration": iteration,
                "mean": mean,
                "low": low,
                "high": high,
            }
        )
    columns = ["group", "metric", "iteration", "mean", "low", "high"]
    return pd.DataFrame(rows, columns=columns).sort_values(["group", "metric", "iteration"])


def summarise_batch(results: BatchResults, geometry: Geometry) -> dict[str, Any]:
    """Every number of the report, per group: competence (competence_summary), strategies
    (strategy_table) and vocal (group -> vocal_summary)."""
    summary = competence_summary(results.trials)
    strategies = strategy_table(results.competence, geometry.hand_limit, geometry.stick_limit)
    vocal = {
        g: vocal_summary(results.vocal[results.vocal["group"] == g], geometry.threshold)
        for g in results.groups
    }
    return {"competence": summary, "strategies": strategies, "vocal": vocal}
