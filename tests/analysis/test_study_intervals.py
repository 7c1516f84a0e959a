"""The intervals of the study's measure: bias-corrected (BC) bootstrap intervals, which contain
their estimate or are not given, and agree with the plain percentile interval where the
resamples are unbiased."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest
from scipy import stats

from experiments.analysis.stats import bias_corrected_interval
from experiments.analysis.study_maps import GRID
from experiments.analysis.study_summary import FULL_COVERAGE, study_summary
from experiments.report.paper import _study_rows, published

RUNS, RESAMPLES = 32, 1000


def _coverage_biased(shift: float) -> tuple[float, np.ndarray]:
    """An estimator biased as the study's renormalised shares are: the mean of 32 runs plus
    `shift` times the share of distinct runs in the sample, which is 1 for the runs themselves
    and about 0.64 in a resample (a resample repeats runs as it repeats pixels). Returns the
    estimate and its bootstrap samples."""
    rng = np.random.default_rng(0)
    runs = rng.normal(0.0, 1.0, RUNS)
    weights = rng.multinomial(RUNS, np.full(RUNS, 1 / RUNS), size=RESAMPLES)
    samples = weights @ runs / RUNS + shift * (weights > 0).mean(axis=1)
    return float(runs.mean() + shift), samples


def test_a_biased_estimate_at_the_edge_of_its_percentile_interval_is_inside_the_bc_one():
    estimate, samples = _coverage_biased(0.7)
    low, high = np.percentile(samples, [2.5, 97.5])
    # The plain percentile interval is lopsided: the estimate in its top 5%.
    assert low < estimate < high and high - estimate < 0.05 * (high - low)
    share = (samples < estimate).mean()
    bc = bias_corrected_interval(samples, estimate)
    assert bc is not None
    assert bc[0] < estimate < bc[1]
    # The method as written: the samples' percentiles at Phi(2 z0 -+ 1.96).
    z0 = stats.norm.ppf(share)
    levels = stats.norm.cdf([2 * z0 - 1.959964, 2 * z0 + 1.959964])
    assert bc == pytest.approx(tuple(np.percentile(samples, 100 * levels)))
    assert bc[0] > low and bc[1] > high  # moved by the bias towards the estimate


def test_an_estimate_outside_its_percentile_interval_gets_no_interval():
    estimate, samples = _coverage_biased(1.0)
    low, high = np.percentile(samples, [2.5, 97.5])
    assert estimate > high  # the percentile interval leaves its own estimate out
    # BC would too (|z0| > 1.96 puts both percentiles on one side): none is given.
    assert bias_corrected_interval(samples, estimate) is None
    assert bias_corrected_interval(samples, np.inf) is None
    assert bias_corrected_interval(np.append(samples, np.nan), 0.0) is None


def test_without_bias_the_bc_interval_is_the_percentile_interval():
    estimate, samples = _coverage_biased(0.0)
    low, high = np.percentile(samples, [2.5, 97.5])
    bc = bias_corrected_interval(samples, estimate)
    assert bc is not None
    assert bc == pytest.approx((low, high), abs=0.05 * (high - low))
    # Resamples that equal the estimate but for rounding count as ties, half below.
    tied = np.full(100, 0.3) + np.random.default_rng(1).normal(0.0, 1e-16, 100)
    assert bias_corrected_interval(tied, 0.3) == pytest.approx((0.3, 0.3))


def _runs_covering_part_of_the_disk(rng: np.random.Generator, n_runs: int, part: float):
    """n_runs runs, each with one test in a random `part` of the disk's pixels."""
    centres = (np.arange(GRID) + 0.5) / (GRID / 2) - 1.0
    x, y = (a.ravel() for a in np.meshgrid(centres, centres, indexing="ij"))
    inside = np.hypot(x, y) < 1.0
    x, y = x[inside], y[inside]
    runs = []
    for k in range(n_runs):
        keep = rng.random(len(x)) < part
        n = int(keep.sum())
        runs.append(
            pd.DataFrame(
                {
                    "x": x[keep],
                    "y": y[keep],
                    "error": rng.uniform(0.0, 1.0, n),
                    "strategy": rng.choice(["hand", "tool", "vocal"], n, p=[0.6, 0.2, 0.2]),
                    "ring": rng.integers(1, 4, n),
                    "trial": f"t{k}",
                }
            )
        )
    return pd.concat(runs, ignore_index=True)


def test_every_interval_of_the_study_summary_contains_its_estimate_or_is_none():
    tests = _runs_covering_part_of_the_disk(np.random.default_rng(7), 12, 0.25)
    summary = study_summary(tests, tests.assign(error=1.0))
    assert summary["coverage"] >= FULL_COVERAGE
    intervals = summary["intervals"]
    pairs = [(summary["competence"]["all"], intervals["competence_all"])]
    for region, shares in summary["strategy_share"].items():
        pairs += [(shares[s], intervals["strategy_share"][region][s]) for s in shares]
    given = [(estimate, bounds) for estimate, bounds in pairs if bounds is not None]
    assert given  # the test would say nothing if every interval were withheld
    for estimate, (low, high) in given:
        assert low <= estimate <= high


def test_the_page_names_the_method_and_says_where_no_interval_is_given():
    numbers = {
        "competence": {"all": 0.43, "ring1": 0.44, "ring2": 0.43, "ring3": 0.42},
        "strategy_share": {
            "centre": {"hand": 0.69, "tool": 0.185, "vocal": 0.12},
            "between_limits": {"hand": 0.56, "tool": 0.25, "vocal": 0.19},
            "distance_1": {"hand": 0.46, "tool": 0.18, "vocal": 0.35},
        },
        "coverage": 0.95,
        "intervals": {
            "competence_all": [0.42, 0.44],
            "strategy_share": {
                "centre": {"hand": [0.68, 0.70], "tool": None, "vocal": [0.11, 0.13]},
                "between_limits": {"hand": None, "tool": None, "vocal": None},
                "distance_1": {"hand": None, "tool": None, "vocal": None},
            },
        },
        "reference_commands_per_ring": 30000,
    }
    rows = _study_rows(["g"], {"g": numbers}, published())
    assert "bias-corrected (BC) bootstrap" in rows[0][0] and "1000 resamples" in rows[0][0]
    assert rows[0][2] == "43% [42%, 44%]"
    (centre,) = [r for r in rows if r[0].startswith("Strategy hand / tool / vocal, centre")]
    assert centre[2] == "69% [68%, 70%] / 18% [no interval] / 12% [11%, 13%]"
