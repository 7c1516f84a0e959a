"""The study's pixel maps (docs/protocol.md §10): competence and Fig. 4's strategy curve from
test rows, as the study's notebooks computed them, and the bootstrap over runs behind their
bias-corrected 95% intervals (`study_summary`).

Tests are pooled per pixel of a GRID x GRID map of [-1, 1]^2 (pixel i holds x in
[i / 50 - 1, (i + 1) / 50 - 1)), distances measured in pixels from pixel (50, 50) as the
notebooks did. Every function works on pooled pixel arrays with a leading axis of samples, so
that the point estimate (one sample: all runs) and the bootstrap over runs (many samples of
runs drawn with replacement, computed at once as a matrix product of run weights) share one
code path.
"""

from __future__ import annotations

import functools
from collections.abc import Iterator

import numpy as np
import pandas as pd

from experiments.analysis.stats import STRATEGIES

GRID = 100  # pixels a side over [-1, 1]^2
CENTRE = GRID // 2  # the pixel the notebooks measured distances from
# Fig. 4's radial bins (pixel-distance int(d) < 50), plotted at x = bin / 49.
STRATEGY_BINS = GRID // 2
BOOTSTRAP_SAMPLES = 1000
BOOTSTRAP_SEED = 2017
BOOTSTRAP_CHUNK = 100


def pixel_indices(table: pd.DataFrame) -> np.ndarray:
    """Flat pixel index i * GRID + j of the rows' x, y."""
    i = np.clip(((table["x"].to_numpy() + 1) / 2 * GRID).astype(int), 0, GRID - 1)
    j = np.clip(((table["y"].to_numpy() + 1) / 2 * GRID).astype(int), 0, GRID - 1)
    return i * GRID + j


@functools.cache
def pixel_distance() -> np.ndarray:
    """(GRID * GRID,) distance of each pixel's index from (CENTRE, CENTRE), in pixels
    (computed once, read-only)."""
    gi, gj = np.meshgrid(np.arange(GRID), np.arange(GRID), indexing="ij")
    distance = np.hypot(gi - CENTRE, gj - CENTRE).ravel()
    distance.flags.writeable = False
    return distance


@functools.cache
def _bin_membership() -> np.ndarray:
    """(GRID * GRID, STRATEGY_BINS) 1 where a pixel belongs to a radial bin of Fig. 4
    (computed once, read-only)."""
    bins = pixel_distance().astype(int)  # int() of a non-negative distance: its floor
    membership = (bins[:, None] == np.arange(STRATEGY_BINS)[None, :]).astype(float)
    membership.flags.writeable = False
    return membership


def pixel_sums(table: pd.DataFrame, runs: np.ndarray | None = None) -> dict[str, np.ndarray]:
    """Per run (rows; one row when `runs` is None) and pixel (GRID * GRID columns): 'count' of
    rows, 'error' summed, and, where the table has a strategy column, one count per strategy.
    `runs`: each row's run number, 0..n_runs - 1."""
    runs = np.zeros(len(table), dtype=int) if runs is None else runs
    n_runs = int(runs.max()) + 1 if len(runs) else 1
    flat = pixel_indices(table)

    def summed(weights) -> np.ndarray:
        out = np.zeros((n_runs, GRID * GRID))
        np.add.at(out, (runs, flat), weights)
        return out

    sums = {"count": summed(1.0)}
    if "error" in table:
        sums["error"] = summed(table["error"].to_numpy(dtype=float))
    if "strategy" in table:
        for strategy in STRATEGIES:
            sums[strategy] = summed((table["strategy"].to_numpy() == strategy).astype(float))
    return sums


def reference_map(reference: pd.DataFrame) -> np.ndarray:
    """(GRID, GRID) random error of each pixel as the study averaged it: the unweighted mean of
    the per-pixel means of every pixel whose distance lies strictly within one pixel of its
    own, among pixels with a mean above 0; NaN where there is none."""
    sums = pixel_sums(reference[["x", "y", "error"]])
    with np.errstate(invalid="ignore", divide="ignore"):
        means = sums["error"][0] / sums["count"][0]
    distance = pixel_distance()
    valid = means > 0  # False for NaN too
    order = np.argsort(distance[valid], kind="stable")
    radii, values = distance[valid][order], means[valid][order]
    cumulative = np.concatenate(([0.0], np.cumsum(values)))
    low = np.searchsorted(radii, distance - 1.0, side="right")
    high = np.searchsorted(radii, distance + 1.0, side="left")
    with np.errstate(invalid="ignore", divide="ignore"):
        averaged = (cumulative[high] - cumulative[low]) / (high - low)
    return np.where(high > low, averaged, np.nan).reshape(GRID, GRID)


def competence_of(sums: dict[str, np.ndarray], random_error: np.ndarray) -> np.ndarray:
    """(samples, GRID * GRID) per-pixel max(0, 1 - agent error / random error) of pooled sums;
    NaN where no test fell or no reference exists (the study drew those pixels grey)."""
    with np.errstate(invalid="ignore", divide="ignore"):
        agent_error = sums["error"] / sums["count"]
        return np.maximum(0.0, 1.0 - agent_error / random_error.ravel())


def curve_of(sums: dict[str, np.ndarray]) -> dict[str, np.ndarray]:
    """Fig. 4's curve of pooled sums: strategy -> (samples, STRATEGY_BINS) shares. Each pixel's
    shares, averaged over the pixels of its bin (a pixel without a test counts 0), then
    renormalised in place one strategy after the other, as the notebook did."""
    membership = _bin_membership()
    pixels_per_bin = membership.sum(axis=0)
    total = sum(sums[s] for s in STRATEGIES)
    curve = {}
    for strategy in STRATEGIES:
        share = np.divide(sums[strategy], total, out=np.zeros_like(total), where=total > 0)
        curve[strategy] = share @ membership / pixels_per_bin
    for strategy in STRATEGIES:
        with np.errstate(invalid="ignore", divide="ignore"):
            curve[strategy] = curve[strategy] / sum(curve[s] for s in STRATEGIES)
    return curve


def bin_positions() -> np.ndarray:
    """Where Fig. 4 plotted each bin: x = bin / 49."""
    return np.arange(STRATEGY_BINS) / (STRATEGY_BINS - 1)


def competence_map(tests: pd.DataFrame, reference: pd.DataFrame) -> np.ndarray:
    """(GRID, GRID) per-pixel competence of tests pooled over runs (see competence_of)."""
    sums = pixel_sums(tests[["x", "y", "error"]])
    return competence_of(sums, reference_map(reference))[0].reshape(GRID, GRID)


def strategy_curve(tests: pd.DataFrame) -> pd.DataFrame:
    """Fig. 4 as the study's notebook computed it: per radial bin (rows 0..49, column `x` where
    it was plotted), the shares of hand, tool and vocal."""
    curve = curve_of(pixel_sums(tests[["x", "y", "strategy"]]))
    table = pd.DataFrame({s: curve[s][0] for s in STRATEGIES})
    table.insert(0, "x", bin_positions())
    return table


def bootstrap_sums(
    tests: pd.DataFrame, samples: int = BOOTSTRAP_SAMPLES, seed: int = BOOTSTRAP_SEED
) -> Iterator[dict[str, np.ndarray]]:
    """Pooled sums of `samples` resamples of the runs (column `trial`) drawn with replacement,
    one row each, yielded BOOTSTRAP_CHUNK rows at a time (a row of every sum is 80 kB); nothing
    with fewer than 2 runs."""
    if "trial" not in tests or tests["trial"].nunique() < 2:
        return
    runs, names = pd.factorize(tests["trial"])
    per_run = pixel_sums(tests, runs)
    rng = np.random.default_rng(seed)
    weights = rng.multinomial(len(names), np.full(len(names), 1 / len(names)), size=samples)
    for start in range(0, samples, BOOTSTRAP_CHUNK):
        chunk = weights[start : start + BOOTSTRAP_CHUNK].astype(float)
        yield {key: chunk @ value for key, value in per_run.items()}
