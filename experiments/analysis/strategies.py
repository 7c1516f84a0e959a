"""Strategy shares under two definitions of "tool", like with like across backends.

The study counted an arm test as "tool" when the stick moved (docs/protocol.md §10, D23). In
the kinematic backend a stick moves only when held; in the physical one it is also pushed, so
the same word would compare a held tool with a nudged stick. Each test row therefore carries
how it touched the stick (`stick_contact`: held, pushed, untouched; measure/evaluation.py) and
the shares are given both ways:
- "study": tool = the stick moved (the `strategy` column, the study's rule);
- "held": tool = the stick was held; an arm test that only pushed the stick counts as hand.

Shares come with intervals over trials (each trial's share of its tests in a region, the
Student t interval of their mean): the trial, not the test, is the independent unit.
"""

from __future__ import annotations

import math

import numpy as np
import pandas as pd

from experiments.analysis.stats import STRATEGIES, mean_ci

# How a test touched the stick, and what moved its goal toy (measure/evaluation.py,
# `movement_contacts`): the stick held, pushed or untouched; the toy held by the hand, caught
# by the stick's tip, brought by the caregiver, pushed by anything else, or not moved.
STICK_CONTACTS = ("held", "pushed", "untouched")
MOVERS = ("hand", "stick", "caregiver", "push", "none")

DEFINITIONS = {
    "study": "tool = the stick moved (the study's rule)",
    "held": "tool = the stick was held (a stick only pushed counts as hand)",
}
COLUMN = {"study": "strategy", "held": "strategy_held"}


def held_strategy(tests: pd.DataFrame) -> pd.Series:
    """Each test's strategy with "tool" meaning the stick was held; NaN-free only where the
    table records it (`stick_contact`, or `stick_grasped` in evaluations before it)."""
    if "stick_contact" in tests.columns and tests["stick_contact"].notna().all():
        held = tests["stick_contact"] == "held"
    elif "stick_grasped" in tests.columns and tests["stick_grasped"].notna().all():
        held = tests["stick_grasped"].astype(bool)
    else:
        return pd.Series(np.nan, index=tests.index, dtype=object)
    arm = tests["strategy"] != "vocal"
    return tests["strategy"].where(~arm, np.where(held, "tool", "hand"))


def with_distance(tests: pd.DataFrame) -> pd.DataFrame:
    """The table with the goal toy's distance from the arm's base (m), computed from x, y where
    the table lacks it (the study's tests)."""
    if "distance" in tests.columns:
        return tests
    return tests.assign(distance=np.hypot(tests["x"], tests["y"]))


def _with_definition(tests: pd.DataFrame, definition: str) -> pd.DataFrame:
    """The tests with their distance and `definition`'s strategy column; no rows where a test
    does not record it (the definition is then not recorded for the batch)."""
    if tests.empty or "strategy" not in tests.columns:
        return tests.iloc[:0]
    tests = with_distance(tests)
    if COLUMN[definition] not in tests.columns:
        tests = tests.assign(strategy_held=held_strategy(tests))
    return tests.iloc[:0] if tests[COLUMN[definition]].isna().any() else tests


def trial_shares(tests: pd.DataFrame, low: float, high: float, definition: str) -> pd.DataFrame:
    """Per trial with tests whose toy lies in [low, high) from the arm's base: each strategy's
    share of them under `definition` ("study" or "held"), and n_tests. Columns trial, group,
    seed (where the tests carry it), hand, tool, vocal, n_tests; no row for a trial without
    tests there. Empty where the tests do not record the definition."""
    keys = [k for k in ("trial", "group", "seed") if k in tests.columns]
    tests = _with_definition(tests, definition)
    inside = tests[(tests["distance"] >= low) & (tests["distance"] < high)] if len(tests) else tests
    if inside.empty:
        return pd.DataFrame(columns=[*keys, *STRATEGIES, "n_tests"])
    column = COLUMN[definition]
    counts = inside.groupby(keys, sort=False)[column].value_counts().unstack(fill_value=0)
    counts = counts.reindex(columns=list(STRATEGIES), fill_value=0)
    n = counts.sum(axis=1)
    shares = counts.div(n, axis=0).assign(n_tests=n)
    return shares.reset_index().rename_axis(columns=None)


def share_intervals(
    tests: pd.DataFrame, regions: dict[str, tuple[float, float]], definition: str
) -> pd.DataFrame:
    """Per group, region and strategy: the mean over trials of each trial's share of its tests
    in the region (`trial_shares`), with its 95% interval; its pooled count of tests,
    n_trials, n_tests. Columns group, definition, region, strategy, mean, low, high, count,
    n_trials, n_tests. No rows for a definition the tests do not record."""
    rows: list[dict] = []
    if _with_definition(tests, definition).empty:
        return pd.DataFrame(rows, columns=_COLUMNS)
    for region, (low, high) in regions.items():
        per_trial = trial_shares(tests, low, high, definition)
        for group in dict.fromkeys(tests["group"]):
            trials = per_trial[per_trial["group"] == group]
            n_tests = trials["n_tests"].to_numpy()
            for strategy in STRATEGIES:
                values = trials[strategy].to_numpy(dtype=float)
                mean, lo, hi = mean_ci(values) if len(values) else (math.nan,) * 3
                rows.append(
                    {
                        "group": group,
                        "definition": definition,
                        "region": region,
                        "strategy": strategy,
                        "mean": mean,
                        "low": lo,
                        "high": hi,
                        "count": int(np.round(values * n_tests).sum()),
                        "n_trials": len(values),
                        "n_tests": int(n_tests.sum()),
                    }
                )
    return pd.DataFrame(rows, columns=_COLUMNS)


_COLUMNS = [
    "group",
    "definition",
    "region",
    "strategy",
    "mean",
    "low",
    "high",
    "count",
    "n_trials",
    "n_tests",
]


def both_definitions(tests: pd.DataFrame, regions: dict[str, tuple[float, float]]) -> pd.DataFrame:
    """`share_intervals` under both definitions, stacked."""
    return pd.concat([share_intervals(tests, regions, d) for d in DEFINITIONS], ignore_index=True)


def contact_counts(tests: pd.DataFrame) -> pd.DataFrame:
    """Per group: arm tests by how they touched the stick (held, pushed, untouched) and what
    moved the goal toy; columns group, what, value, count. Empty where not recorded."""
    rows = []
    for what in ("stick_contact", "goal_moved_by"):
        if what not in tests.columns or tests[what].isna().any():
            continue
        arm = tests[tests["strategy"] != "vocal"] if what == "stick_contact" else tests
        sizes = arm.groupby(["group", what], sort=False).size()
        for (group, value), count in zip(sizes.index.tolist(), sizes.tolist(), strict=True):
            rows.append({"group": group, "what": what, "value": value, "count": int(count)})
    return pd.DataFrame(rows, columns=["group", "what", "value", "count"])
