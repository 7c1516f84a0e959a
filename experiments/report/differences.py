"""The measures of the registry (experiments/report/measures.py) on two sides: per-trial
values, the tests of their differences over trials, Holm's correction over every test the page
makes, and the table and summary.json sections that show them.

Each measure's parts are tested on one value per trial (experiments/analysis/trial_tests.py),
paired over seeds where the sides hold the same seeds; a part a backend fixes by construction
is shown without a test; pooled tests are second lines, never counted in the correction. Beside
every t, a nonparametric test of the same values (the Wilcoxon signed-rank test where the t is
paired or against 0, the Mann-Whitney U test where the sides do not pair), with its own Holm
adjustment over the same family (`FAMILY`); the cells whose star differs between the two are
named (`disagreement_lines`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from typing import Any

import numpy as np
import pandas as pd

from experiments.analysis.results import BatchResults
from experiments.analysis.stats import mean_ci
from experiments.analysis.trial_tests import (
    ALPHA,
    PooledTest,
    TrialTest,
    difference_test,
    holm,
    one_sample_test,
    seeds_pair,
    survives,
)
from experiments.analysis.trial_values import VALUE
from experiments.report.measures import GAP, NONE, Measure
from experiments.report.pages import num, p_value, pct

INTERACTION = "interaction"
# The page's one family of tests, fixed by the registry and the sides' groups before any value
# is compared: Holm's correction runs over all of it, once for the t and once for the
# nonparametric p.
FAMILY = (
    "every part of every measure of the registry (experiments/report/measures.py) that both "
    "sides recorded and that no backend fixes by construction: the sides' per-trial values "
    "compared; for a gap measure, each side's gap against 0 and their interaction"
)


@dataclass(frozen=True)
class Outcome:
    """One per-trial test of the page: a measure's part, a group's gap against 0 (`part` the
    group) or the interaction of a gap measure; its t's p and its nonparametric p
    (`test.rank_p`) each Holm-adjusted over the page's tests."""

    measure: str
    part: str
    test: TrialTest
    groups: tuple[str, ...]
    holm_p: float = math.nan
    rank_holm_p: float = math.nan

    @property
    def survives(self) -> bool:
        return survives(self.holm_p)

    @property
    def rank_survives(self) -> bool:
        return survives(self.rank_holm_p)


@dataclass(frozen=True)
class Evaluated:
    """A measure on two sides: their per-trial values, its outcomes, the parts not tested
    (part, why) and its pooled second lines."""

    measure: Measure
    values: tuple[pd.DataFrame, pd.DataFrame]
    outcomes: tuple[Outcome, ...]
    untested: tuple[tuple[str, str], ...]
    pooled: tuple[PooledTest, ...]


def _by_seed(values: pd.DataFrame, part: str) -> pd.Series:
    return values.set_index("seed")[part]


def _all_missing(values: pd.DataFrame, parts: tuple[str, ...]) -> bool:
    return bool(values[list(parts)].isna().all(axis=None))


def fixed_reason(measure: Measure, part: str, side: BatchResults, values: pd.DataFrame) -> str:
    """Why `part` is not tested on `side` (its backend fixes it, and every value it holds is
    that one), or "" where it is to be tested."""
    finite = values[part].dropna().to_numpy(dtype=float)
    for fixed in measure.fixed:
        if (fixed.parts is None or part in fixed.parts) and fixed.declared(side.trials):
            if len(finite) and np.all(finite == fixed.value):
                return f"{side.groups[0]}: {fixed.reason}"
    return ""


def _evaluate(measure: Measure, a: BatchResults, b: BatchResults, paired: bool) -> Evaluated:
    sides = (a, b)
    values = (measure.values(a), measure.values(b))
    groups = (a.groups[0], b.groups[0])
    outcomes: list[Outcome] = []
    untested: list[tuple[str, str]] = []
    missing = [
        s.groups[0] for s, v in zip(sides, values, strict=True) if _all_missing(v, measure.parts)
    ]
    if measure.test == NONE:
        untested.append(("", measure.untested))
    elif missing:
        untested.append(("", f"{', '.join(missing)}: {measure.missing}"))
    for part in () if missing else measure.tested_parts:
        reasons = [fixed_reason(measure, part, s, v) for s, v in zip(sides, values, strict=True)]
        if any(reasons):
            untested.append((part, "; ".join(r for r in reasons if r)))
            continue
        first, second = (_by_seed(v, part) for v in values)
        if measure.test == GAP:
            for group, s in zip(groups, (first, second), strict=True):
                outcomes.append(Outcome(measure.name, group, one_sample_test(s), (group,)))
            outcomes.append(
                Outcome(measure.name, INTERACTION, difference_test(first, second, paired), groups)
            )
        else:
            outcomes.append(
                Outcome(measure.name, part, difference_test(first, second, paired), groups)
            )
    # A pooled test of a part fixed by construction would test the construction too.
    fixed_parts = any(part for part, _ in untested)
    pooled = measure.pooled(a, b) if measure.pooled and not missing and not fixed_parts else []
    return Evaluated(measure, values, tuple(outcomes), tuple(untested), tuple(pooled))


def evaluate(measures: tuple[Measure, ...], a: BatchResults, b: BatchResults) -> list[Evaluated]:
    """Every measure both sides recorded something of, tested, with Holm's adjustment of each
    kind of p over every outcome with one. Paired over seeds where the sides hold the same
    seeds."""
    paired = seeds_pair(list(a.trials["seed"]), list(b.trials["seed"]))
    evaluated = [_evaluate(m, a, b, paired) for m in measures]
    evaluated = [
        e for e in evaluated if not all(_all_missing(v, e.measure.parts) for v in e.values)
    ]
    outcomes = [o for e in evaluated for o in e.outcomes]
    adjusted = iter(holm([o.test.p for o in outcomes]))
    rank_adjusted = iter(holm([o.test.rank_p for o in outcomes]))

    def adjust(o: Outcome) -> Outcome:
        return replace(o, holm_p=float(next(adjusted)), rank_holm_p=float(next(rank_adjusted)))

    return [replace(e, outcomes=tuple(adjust(o) for o in e.outcomes)) for e in evaluated]


# Text ------------------------------------------------------------------------------------------


def value_text(kind: str, x: float) -> str:
    """A value of a measure of `kind` as the pages print it."""
    if kind == "share":
        return pct(x, 1)
    if kind == "seconds":
        return "n/a" if not np.isfinite(x) else f"{1000 * x:.2f} ms / iteration"
    return num(x, {"distance": 3, "ratio": 2, "iteration": 0}.get(kind, 1))


def side_text(measure: Measure, side: BatchResults, values: pd.DataFrame) -> str:
    """A side's mean over trials of each part with its 95% t interval, the trials behind it
    and the note of what they rest on."""
    if _all_missing(values, measure.parts):
        return measure.missing
    cells = []
    for part in measure.parts:
        mean, low, high = mean_ci(values[part].to_numpy(dtype=float))
        text = value_text(measure.kind, mean)
        if np.isfinite(low):
            text += f" [{value_text(measure.kind, low)}, {value_text(measure.kind, high)}]"
        cells.append(text if part == VALUE else f"{part} {text}")
    n = int(np.isfinite(values[list(measure.parts)].to_numpy(dtype=float)).any(axis=1).sum())
    note = measure.note(side) if measure.note else ""
    return f"{', '.join(cells)} (n={n} trials{'; ' + note if note else ''})"


def _method(outcomes: tuple[Outcome, ...]) -> str:
    test = outcomes[0].test
    if test.paired:
        return f"{test.method} ({test.n[0]} pairs)"
    return f"{test.method} ({' + '.join(map(str, test.n))} trials)"


def _labelled(outcomes: tuple[Outcome, ...], text) -> str:
    if len(outcomes) == 1 and outcomes[0].part in (VALUE, INTERACTION):
        return text(outcomes[0])
    return "; ".join(f"{o.part} {text(o)}" for o in outcomes)


def holm_text(outcomes: tuple[Outcome, ...]) -> str:
    """Which outcomes survive Holm's correction (those without a p are not in it)."""
    made = tuple(o for o in outcomes if np.isfinite(o.holm_p))
    return _labelled(made, lambda o: "survives" if o.survives else "no") if made else ""


def rank_holm_text(outcomes: tuple[Outcome, ...]) -> str:
    """Which outcomes' nonparametric p survives Holm's correction."""
    made = tuple(o for o in outcomes if np.isfinite(o.rank_holm_p))
    return _labelled(made, lambda o: "survives" if o.rank_survives else "no") if made else ""


def rank_cell(outcomes: tuple[Outcome, ...]) -> str:
    """The nonparametric test beside the t of `outcomes` (one method for all), with its p."""
    if not outcomes:
        return ""
    ps = _labelled(outcomes, lambda o: p_value(o.test.rank_p))
    return f"{outcomes[0].test.rank_method}: {ps}"


def outcome_p(outcome: Outcome) -> str:
    """An outcome's p, or why it has none."""
    test = outcome.test
    if np.isfinite(test.p):
        return p_value(test.p)
    return "n/a (fewer than 2 trials)" if min(test.n) < 2 else "n/a (no variance)"


def _untested_text(e: Evaluated) -> str:
    return "; ".join(
        f"{part + ' ' if part not in ('', VALUE) else ''}not tested: {why}"
        for part, why in e.untested
    )


def _ratio(e: Evaluated, groups: list[str]) -> str:
    """The ratio of the sides' means, for a measure never tested (a cost)."""
    if e.measure.test != NONE:
        return ""
    means = [
        float(np.nanmean(v[VALUE])) if not _all_missing(v, (VALUE,)) else math.nan for v in e.values
    ]
    if not all(np.isfinite(means)) or means[0] <= 0:
        return ""
    return f"ratio {groups[1]} / {groups[0]}: {means[1] / means[0]:.2f}×"


def rows(evaluated: list[Evaluated], a: BatchResults, b: BatchResults) -> list[list[str]]:
    """The table of differences: [measure, A, B, test, p, Holm] per measure (a gap measure
    gives a row of each group against 0 and one of the interaction), each pooled test on a
    second line below its measure."""
    groups = [a.groups[0], b.groups[0]]
    out = []
    for e in evaluated:
        m = e.measure
        sides = [side_text(m, s, v) for s, v in zip((a, b), e.values, strict=True)]
        within = tuple(o for o in e.outcomes if o.part != INTERACTION)
        if m.test == GAP and e.outcomes:
            out.append(
                [
                    f"{m.label}, against 0",
                    *sides,
                    _method(within[:1]) + " per group",
                    _labelled(within, outcome_p),
                    holm_text(within),
                    rank_cell(within),
                    rank_holm_text(within),
                ]
            )
            # The interaction: do the groups' per-trial values differ (the gaps, compared)?
            both = tuple(o for o in e.outcomes if o.part == INTERACTION)
            difference = value_text(m.kind, both[0].test.difference)
            out.append(
                [
                    f"└ {m.short or m.label}: {groups[0]} vs {groups[1]} (interaction)",
                    "",
                    "",
                    f"{_method(both)}; {groups[0]} − {groups[1]}: {difference}",
                    outcome_p(both[0]),
                    holm_text(both),
                    rank_cell(both),
                    rank_holm_text(both),
                ]
            )
        else:
            test = ", ".join(x for x in (_method(within) if within else "", _untested_text(e)) if x)
            p = _labelled(within, outcome_p) if within else _ratio(e, groups)
            tests = [holm_text(within), rank_cell(within), rank_holm_text(within)]
            out.append([m.label, *sides, test, p, *tests])
        out += _pooled_rows(e, groups)
    return out


def _pooled_rows(e: Evaluated, groups: list[str]) -> list[list[str]]:
    if not e.pooled:
        return []
    what = e.pooled[0].what
    label = f"└ the same, pooled over {what} (treats {what} as independent)"
    if len(e.pooled) == 2 and e.measure.test == GAP:  # one pooled test per group
        cells = [p_value(t.p) for t in e.pooled]
        return [[label, *cells, f"{e.pooled[0].method}, per group", "", "not counted", "", ""]]
    return [[label, "", "", t.method, p_value(t.p), "not counted", "", ""] for t in e.pooled]


# summary.json ----------------------------------------------------------------------------------


def _finite_or_none(x: float) -> float | None:
    return float(x) if np.isfinite(x) else None


def tests_summary(evaluated: list[Evaluated]) -> dict[str, Any]:
    """Every per-trial test (name, statistic, p, n per group, paired or not, Holm-adjusted p,
    survives; the nonparametric test beside it: its name, p, Holm-adjusted p, survives), the
    family, the pooled second lines and the parts not tested, for summary.json."""
    outcomes = [o for e in evaluated for o in e.outcomes]
    tests = [
        {
            "measure": o.measure,
            "part": o.part,
            "method": o.test.method,
            "statistic": _finite_or_none(o.test.statistic),
            "difference": _finite_or_none(o.test.difference),
            "p": _finite_or_none(o.test.p),
            "n": dict(zip(o.groups, o.test.n, strict=True)),
            "paired": o.test.paired,
            "holm_p": _finite_or_none(o.holm_p),
            "survives": o.survives,
            "rank_method": o.test.rank_method,
            "rank_p": _finite_or_none(o.test.rank_p),
            "rank_holm_p": _finite_or_none(o.rank_holm_p),
            "rank_survives": o.rank_survives,
        }
        for o in outcomes
    ]
    return {
        "correction": "Holm",
        "alpha": ALPHA,
        "family": FAMILY,
        "count": int(sum(np.isfinite(o.test.p) for o in outcomes)),
        "survive": int(sum(o.survives for o in outcomes)),
        "survive_rank": int(sum(o.rank_survives for o in outcomes)),
        "tests": tests,
        "pooled": [
            {
                "measure": e.measure.name,
                "method": t.method,
                "statistic": _finite_or_none(t.statistic),
                "p": _finite_or_none(t.p),
                "pooled_over": t.what,
            }
            for e in evaluated
            for t in e.pooled
        ],
        "not_tested": [
            {"measure": e.measure.name, "part": part, "reason": why}
            for e in evaluated
            for part, why in e.untested
        ],
    }


def per_trial_values(measures: tuple[Measure, ...], results: BatchResults) -> dict[str, Any]:
    """Each measure's value per trial, for summary.json: its label, kind, parts and test, and
    `per_trial`, columns of equal length: trial, group, seed, then one per part (null where a
    trial has no value: nothing to measure there, or a distance never reached)."""
    out = {}
    for m in measures:
        values = m.values(results)
        if _all_missing(values, m.parts):
            continue
        out[m.name] = {
            "label": m.label,
            "kind": m.kind,
            "parts": list(m.parts),
            "test": m.test,
            "per_trial": {
                "trial": [str(t) for t in values["trial"]],
                "group": [str(g) for g in values["group"]],
                "seed": [int(s) for s in values["seed"]],
                **{p: [_finite_or_none(float(x)) for x in values[p]] for p in m.parts},
            },
        }
    return out
