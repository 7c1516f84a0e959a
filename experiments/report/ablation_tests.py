"""The ablation table's measures (those of the registry marked `in_ablations`,
experiments/report/measures.py), tested over trials: each configuration's per-trial
values against the baseline's on the same seeds (the paired t test of their differences), a gap
measure's values also against 0 within the row, and Holm's correction over every test of the
table (experiments/analysis/trial_tests.py).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from experiments.analysis.results import BatchResults
from experiments.analysis.stats import paired_difference
from experiments.analysis.trial_tests import holm, one_sample_test, paired_arrays, survives
from experiments.analysis.trial_values import VALUE
from experiments.report.differences import value_text
from experiments.report.measures import GAP, Measure
from experiments.report.pages import p_value


@dataclass(frozen=True)
class AblationNumbers:
    """One measure on one row: its mean over the row's trials (n of them with a value); the
    mean paired difference from the baseline on the seeds both hold (95% interval, paired t p,
    n_pairs; NaN for the baseline's own row); for a gap measure, the row's values against 0
    (`within_p`); each p with its Holm-adjusted value over the table's tests."""

    mean: float
    n: int
    difference: float = math.nan
    low: float = math.nan
    high: float = math.nan
    p: float = math.nan
    n_pairs: int = 0
    within_p: float = math.nan
    holm_p: float = math.nan
    within_holm_p: float = math.nan


def ablation_measures(measures: tuple[Measure, ...]) -> tuple[Measure, ...]:
    """The measures of the ablation table: one part each, marked for it in the registry."""
    return tuple(m for m in measures if m.in_ablations and m.parts == (VALUE,))


def numbers(
    measure: Measure, results: BatchResults, baseline: BatchResults | None
) -> AblationNumbers:
    """`measure` on a row's trials (one group), against `baseline`'s trials of the same group
    (None: the baseline's own row)."""
    mine = measure.values(results).set_index("seed")[VALUE]
    finite = mine.to_numpy(dtype=float)
    finite = finite[np.isfinite(finite)]
    mean = float(finite.mean()) if len(finite) else math.nan
    within = one_sample_test(mine).p if measure.test == GAP else math.nan
    out = AblationNumbers(mean, len(finite), within_p=within)
    if baseline is None:
        return out
    theirs = measure.values(baseline).set_index("seed")[VALUE]
    x, y = paired_arrays(mine, theirs)
    difference, low, high, p = paired_difference(x, y)
    return replace(out, difference=difference, low=low, high=high, p=p, n_pairs=len(x))


def with_holm(table: list[dict[str, AblationNumbers]]) -> list[dict[str, AblationNumbers]]:
    """Each row's numbers (measure name -> numbers) with Holm's adjustment over every p of the
    table: the paired differences and the gaps against 0."""
    ps = [p for row in table for n in row.values() for p in (n.p, n.within_p)]
    adjusted = iter(holm(ps))
    return [
        {
            name: replace(n, holm_p=float(next(adjusted)), within_holm_p=float(next(adjusted)))
            for name, n in row.items()
        }
        for row in table
    ]


def count_tests(table: list[dict[str, AblationNumbers]]) -> tuple[int, int]:
    """(tests made, tests that survive Holm) of the table."""
    pairs = [(n.p, n.holm_p) for row in table for n in row.values()]
    pairs += [(n.within_p, n.within_holm_p) for row in table for n in row.values()]
    made = [adjusted for p, adjusted in pairs if np.isfinite(p)]
    return len(made), sum(survives(a) for a in made)


def _signed(kind: str, x: float) -> str:
    """A difference of a measure of `kind`: percentage points for shares."""
    return f"{100 * x:+.1f}" if kind == "share" else f"{x:+.3f}"


def _holm_mark(adjusted: float) -> str:
    return ", survives Holm" if survives(adjusted) else ""


def cell(measure: Measure, n: AblationNumbers) -> str:
    """A row's cell of `measure`: its mean, and for an ablation its paired difference from the
    baseline, [95% CI], the paired t test's p, the pairs and whether it survives Holm."""
    text = value_text(measure.kind, n.mean)
    if math.isfinite(n.difference):
        interval = (
            f" [{_signed(measure.kind, n.low)}, {_signed(measure.kind, n.high)}]"
            if math.isfinite(n.low)
            else ""
        )
        text += (
            f" ({_signed(measure.kind, n.difference)}{interval}, {p_value(n.p)}, "
            f"{n.n_pairs} pairs{_holm_mark(n.holm_p)})"
        )
    return text


def within_cell(n: AblationNumbers) -> str:
    """A gap measure's row against 0: its one-sample p over trials."""
    return f"{p_value(n.within_p)}{_holm_mark(n.within_holm_p)}"


def header(measure: Measure) -> str:
    """The table's column of `measure`."""
    what = "difference from the baseline" if measure.test != GAP else "difference of the gaps"
    return (
        f"{measure.label}: mean over trials ({what} paired by seed [95% CI], paired t p over seeds)"
    )
