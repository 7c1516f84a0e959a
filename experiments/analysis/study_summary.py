"""The study's own summary of its tests (docs/protocol.md §10, D20-D23): the mean per-pixel
competence and the strategy shares of Fig. 4's regions, pooled over runs, from the tests of a
batch and the random reference played for its settings (experiments/measure/study_measure.py
plays both). Pure computation on tables: no room is built here."""

from __future__ import annotations

import warnings
from typing import Any

import numpy as np
import pandas as pd

from experiments.analysis.stats import STRATEGIES, bias_corrected_interval
from experiments.analysis.study_maps import (
    STRATEGY_BINS,
    bin_positions,
    bootstrap_sums,
    competence_of,
    curve_of,
    pixel_distance,
    pixel_sums,
    reference_map,
)

# Below this share of the disk's pixels holding a test, the notebook's renormalisation leaves
# the strategy shares summing below 1 (the report flags them) and intervals are not computed.
FULL_COVERAGE = 0.9
# 10000 placements per ring, one random command per toy (notebook motor_babbling).
RANDOM_COMMANDS_PER_RING = 30000
# Fig. 4's limits (the hand's reach plus its grasp distance, the stick's), on its plotted axis.
HAND_LIMIT, STICK_LIMIT = 0.6, 0.85


def study_summary(tests: pd.DataFrame, reference: pd.DataFrame) -> dict:
    """The study's numbers: mean per-pixel competence (all rings and per ring) and the
    strategy shares of its regions, read off Fig. 4's curve; with a `trial` column and tests
    in at least FULL_COVERAGE of the disk's pixels, their 95% bias-corrected (BC) bootstrap
    intervals over study_maps.BOOTSTRAP_SAMPLES resamples of the runs drawn with replacement
    ('intervals': [low, high], or None where the estimate lies outside the central 95% of its
    resamples; `stats.bias_corrected_interval`).

    Why bias-corrected: a resample repeats runs, so it covers fewer pixels than the runs it
    came from, and the notebook's renormalisation then lowers every share. The plain
    percentile intervals used before were lopsided even at 32 runs (94.6% of the pixels: tool
    near the centre 18.5% [16.7, 18.9]); BC shifts the percentiles by the resamples' bias.
    Why none below FULL_COVERAGE: there the bias outgrows the interval (16 runs, 79% of the
    pixels: tool near the centre 20% [16, 19] by percentiles)."""
    random_error = reference_map(reference)
    x = bin_positions()
    regions = {
        "centre": x < HAND_LIMIT,
        "between_limits": (x >= HAND_LIMIT) & (x < STICK_LIMIT),
        "distance_1": np.arange(len(x)) == len(x) - 1,
    }

    def mean_competence(sums: dict[str, np.ndarray]) -> np.ndarray:
        with warnings.catch_warnings():  # no pixel with a test: NaN, said by the table
            warnings.simplefilter("ignore", RuntimeWarning)
            return np.nanmean(competence_of(sums, random_error), axis=1)

    def numbers(sums: dict[str, np.ndarray]) -> tuple[np.ndarray, dict]:
        competence = mean_competence(sums)
        with warnings.catch_warnings():  # a region without tests is NaN, said by the table
            warnings.simplefilter("ignore", RuntimeWarning)
            curve = curve_of(sums)
            shares = {
                name: {s: np.nanmean(curve[s][:, mask], axis=1) for s in STRATEGIES}
                for name, mask in regions.items()
            }
        return competence, shares

    pooled = pixel_sums(tests)
    competence, shares = numbers(pooled)
    disk = pixel_distance() < STRATEGY_BINS
    summary: dict[str, Any] = {
        # The notebook's renormalisation assumes nearly every pixel holds a test (100 runs):
        # with few, a bin's shares sum to less than 1.
        "coverage": float((pooled["count"][0][disk] > 0).mean()),
        "competence": {"all": float(competence[0])},
        "strategy_share": {
            name: {s: float(v[0]) for s, v in by_strategy.items()}
            for name, by_strategy in shares.items()
        },
    }
    for ring, table in tests.groupby("ring"):
        ring_sums = pixel_sums(table[["x", "y", "error"]])
        summary["competence"][f"ring{ring}"] = float(mean_competence(ring_sums)[0])
    if summary["coverage"] < FULL_COVERAGE:
        return summary
    samples = [numbers(sums) for sums in bootstrap_sums(tests)]
    if samples:

        def interval(values: list[np.ndarray], estimate: float) -> list[float] | None:
            bounds = bias_corrected_interval(np.concatenate(values), estimate)
            return None if bounds is None else list(bounds)

        summary["intervals"] = {
            "competence_all": interval([c for c, _ in samples], summary["competence"]["all"]),
            "strategy_share": {
                name: {
                    s: interval(
                        [sh[name][s] for _, sh in samples], summary["strategy_share"][name][s]
                    )
                    for s in STRATEGIES
                }
                for name in regions
            },
        }
    return summary
