"""The ablation table's numbers (`AblationRow`: one configuration's; `AblationNumbers`: one
measure's on it) and its measures (those of the registry marked `in_ablations`,
experiments/report/measures.py), tested over trials: each configuration's per-trial
values against the baseline's on the same seeds (the paired t test of their differences, and
beside it Wilcoxon's signed-rank test of the same differences), a gap measure's values also
against 0 within the row (the one-sample t and the signed-rank test), and Holm's correction
over the table's one family of tests (`FAMILY`, fixed by the rows and the measures before any
value is read) for each kind of p (experiments/analysis/trial_tests.py, step_split.py).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np
import pandas as pd

from experiments.analysis import step_split
from experiments.analysis.results import BatchResults
from experiments.analysis.trial_tests import one_sample_test
from experiments.analysis.trial_values import VALUE
from experiments.report.differences import value_text
from experiments.report.measures import GAP, Measure
from experiments.report.paired_text import cell_text, p_text, rank_text

# The table's one family of tests, fixed by its rows and measures before any value is read:
# Holm's correction runs over all of it, once for the t and once for the signed-rank p.
FAMILY = (
    "every measure of the table: each configuration's paired difference from the baseline, on "
    "the seeds both hold",
    "every gap measure (names against distractors): each row's per-trial values against 0, "
    "the baseline's row too",
)
# The two kinds of test of the family (`declared_tests`' `test` column).
DIFFERENCE_TEST, AGAINST_ZERO = "difference from the baseline", "against 0"


@dataclass(frozen=True)
class AblationNumbers:
    """One measure on one row: its mean over the row's trials (n of them with a value); the
    mean paired difference from the baseline on the seeds both hold (95% interval, paired t p,
    n_pairs; NaN for the baseline's own row); for a gap measure, the row's values against 0
    (`within_p`); each p with its Holm-adjusted value over the table's family; beside each t's p
    the signed-rank test's (`rank_p`, `within_rank_p`) and its own Holm adjustment.
    `against_baseline`: the row is set against the baseline (its difference is a test of the
    family, whether or not it could be made)."""

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
    rank_p: float = math.nan
    within_rank_p: float = math.nan
    rank_holm_p: float = math.nan
    within_rank_holm_p: float = math.nan
    against_baseline: bool = False


@dataclass(frozen=True)
class AblationRow:
    """One configuration's numbers; shares are fractions, NaN where not measured."""

    label: str
    batch: str
    group: str
    n_trials: int
    study_competence: float
    study_strategies: dict[str, dict[str, float]]  # region -> strategy -> share
    # The registry's measures of this table (name -> numbers over trials, paired by seed).
    measures: dict[str, AblationNumbers]
    # The study's numbers on the pooled words: medians, and the Mann-Whitney p of names vs
    # distractors, two-sided as the study (the one-sided p doubled); treats words as independent.
    median_names: float
    median_distractors: float
    pooled_names_vs_distractors_p_two_sided: float


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
    out = AblationNumbers(mean, len(finite))
    if measure.test == GAP:
        within = one_sample_test(mine)
        out = replace(out, within_p=within.p, within_rank_p=within.rank_p)
    if baseline is None:
        return out
    theirs = measure.values(baseline).set_index("seed")[VALUE]
    test = step_split.paired_test(mine, theirs)
    return replace(
        out,
        difference=test["mean"],
        low=test["low"],
        high=test["high"],
        p=test["p"],
        rank_p=test["p_rank"],
        n_pairs=int(test["n"]),
        against_baseline=True,
    )


DECLARED_COLUMNS = ["row", "measure", "test", "p", "p_rank", "p_holm", "p_rank_holm"]


def declared_tests(
    table: list[dict[str, AblationNumbers]], measures: tuple[Measure, ...]
) -> pd.DataFrame:
    """Every test of the family (FAMILY), one row each: the table's row (its index), the
    measure, the test (DIFFERENCE_TEST or AGAINST_ZERO), both kinds of p and their Holm
    adjustments as the numbers hold them (NaN before `with_holm`; a test that could not be made
    has no p and does not count in Holm's m)."""
    rows = []
    for i, row in enumerate(table):
        for m in measures:
            n = row[m.name]
            if n.against_baseline:
                ps = (n.p, n.rank_p, n.holm_p, n.rank_holm_p)
                rows.append([i, m.name, DIFFERENCE_TEST, *ps])
            if m.test == GAP:
                ps = (n.within_p, n.within_rank_p, n.within_holm_p, n.within_rank_holm_p)
                rows.append([i, m.name, AGAINST_ZERO, *ps])
    return pd.DataFrame(rows, columns=DECLARED_COLUMNS)


def with_holm(
    table: list[dict[str, AblationNumbers]], measures: tuple[Measure, ...]
) -> list[dict[str, AblationNumbers]]:
    """Each row's numbers (measure name -> numbers) with Holm's adjustment of each kind of p
    over the family: the paired differences and the gaps against 0."""
    tests = declared_tests(table, measures).drop(columns=["p_holm", "p_rank_holm"])
    (adjusted,) = step_split.with_holm(tests)
    out = [dict(row) for row in table]
    for t in adjusted.to_dict("records"):
        n = out[t["row"]][t["measure"]]
        holm_p, rank_holm_p = float(t["p_holm"]), float(t["p_rank_holm"])
        if t["test"] == DIFFERENCE_TEST:
            n = replace(n, holm_p=holm_p, rank_holm_p=rank_holm_p)
        else:
            n = replace(n, within_holm_p=holm_p, within_rank_holm_p=rank_holm_p)
        out[t["row"]][t["measure"]] = n
    return out


def count_tests(
    table: list[dict[str, AblationNumbers]], measures: tuple[Measure, ...]
) -> dict[str, int]:
    """The family's size, the tests that could be made, and how many survive Holm with the t
    and with the signed-rank test (step_split.counts)."""
    return step_split.counts([declared_tests(table, measures)])


def cell(measure: Measure, n: AblationNumbers) -> str:
    """A row's cell of `measure`: its mean, and for an ablation its paired difference from the
    baseline [95% CI], the paired t's p, the signed-rank p and the pairs, each p with * where
    it survives Holm (paired_text.cell_text, as the contact ladder writes a step)."""
    text = value_text(measure.kind, n.mean)
    if not n.against_baseline:
        return text
    test = {"mean": n.difference, "low": n.low, "high": n.high, "p": n.p, "p_holm": n.holm_p}
    test |= {"p_rank": n.rank_p, "p_rank_holm": n.rank_holm_p, "n": n.n_pairs}
    return f"{text} ({cell_text(measure.kind, test)})"


def within_cell(n: AblationNumbers) -> str:
    """A gap measure's row against 0: its one-sample t's p and its signed-rank p over trials,
    each with * where it survives Holm."""
    rank = rank_text(n.within_rank_p, n.within_rank_holm_p)
    return f"{p_text(n.within_p, n.within_holm_p)}; {rank}"


def header(measure: Measure) -> str:
    """The table's column of `measure`."""
    what = "difference from the baseline" if measure.test != GAP else "difference of the gaps"
    return (
        f"{measure.label}: mean over trials ({what} paired by seed [95% CI], paired t p; "
        "Wilcoxon signed-rank p (pairs))"
    )


def gap_header(measure: Measure) -> str:
    """The table's column of a gap measure's rows against 0."""
    return (
        f"{measure.short or measure.label}: against 0, one-sample t p over trials; Wilcoxon "
        "signed-rank p"
    )
