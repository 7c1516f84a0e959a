"""A step between two conditions, paired by seed, and its split by the world that tests the
agents: the one definition the contact ladder's page (experiments/report/ladder.py) and
`python -m experiments.analysis.world_steps` share.

For conditions A and B (two rungs of the ladder, or a condition and its ablation) whose agents
were tested in their own worlds ("own") and in a test world W (`playroom eval DIR --world W`):
- `whole`: B's agents in B's own world against A's in A's own, B own - A own;
- `both_in_world`: B's agents against A's, both tested in W, B in W - A in W. It is what the
  agents differ by when one world tests both; it is not "what they learned" alone, since W may
  reward one kind of agent more than another;
- `own_against_world`: (B own - B in W) - (A own - A in W): how much more B's own world scores
  B's agents than W does, minus the same for A. Where A's own world is W (the ladder's first
  rung in the kinematic world, its last in the physical one) the second bracket is 0 and this is
  B's own world against W for B's agents; for two rungs neither of whose worlds is W (the
  ladder's middle rungs) it contrasts three worlds, B's own, A's own and W, and is not what
  either rung's own world does alone.
The two parts add up to the whole, seed by seed.

Every difference is `paired_test`: the mean over the seeds both hold of B minus A with its
Student t 95% interval, the paired t test's two-sided p and, beside it, the Wilcoxon
signed-rank test's (trial_tests.signed_rank_p); both NaN where every difference is equal (no
test: it does not count in Holm's m). `with_holm` adjusts each kind of p over one family and
`survives` (adjusted p <= ALPHA) stars a cell, on every page that uses this module.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import pandas as pd

from experiments.analysis.stats import paired_difference
from experiments.analysis.trial_tests import holm, paired_arrays, signed_rank_p, survives

WHOLE, BOTH_IN_WORLD, OWN_AGAINST_WORLD = "whole", "both_in_world", "own_against_world"
PARTS = (BOTH_IN_WORLD, OWN_AGAINST_WORLD)
# What each part computes, for the pages ({world}: the test world; A, B: the two conditions).
PART_TEXT = {
    WHOLE: "whole step (each in its own world)",
    BOTH_IN_WORLD: "both tested in the {world} world (B in it - A in it)",
    OWN_AGAINST_WORLD: (
        "own worlds against the {world} world ((B own - B in it) - (A own - A in it))"
    ),
}
# The same, short (lists that name a test).
PART_SHORT = {
    WHOLE: "whole step",
    BOTH_IN_WORLD: "both tested in the {world} world",
    OWN_AGAINST_WORLD: "own worlds against the {world} world",
}
# The two kinds of p of every test, and their Holm-adjusted columns.
P_COLUMNS = {"p": "p_holm", "p_rank": "p_rank_holm"}
TEST_COLUMNS = ("mean", "low", "high", "p", "p_rank", "n")


def paired_test(b: pd.Series, a: pd.Series) -> dict[str, float]:
    """B minus A (per-trial values indexed by seed) over the seeds both hold, a pair with a
    value that is not finite left out: mean, 95% interval, paired t p, signed-rank p, n."""
    x, y = paired_arrays(b, a)
    mean, low, high, p = paired_difference(x, y)
    rank = signed_rank_p(x - y) if np.isfinite(p) else float("nan")
    return {"mean": mean, "low": low, "high": high, "p": p, "p_rank": rank, "n": len(x)}


def split_step(
    a_own: pd.Series, b_own: pd.Series, a_in: pd.Series, b_in: pd.Series
) -> dict[str, dict[str, float]]:
    """The two parts of the step from A to B for one test world: each condition's per-trial
    values (indexed by seed) in its own world and in the test world. Part -> paired_test."""
    own_against = (b_own - b_in) - (a_own - a_in)  # per seed; NaN where one lacks it
    zero = pd.Series(0.0, index=own_against.index)
    return {
        BOTH_IN_WORLD: paired_test(b_in, a_in),
        OWN_AGAINST_WORLD: paired_test(own_against.dropna(), zero),
    }


def with_holm(*tables: pd.DataFrame) -> tuple[pd.DataFrame, ...]:
    """The tables with p_holm and p_rank_holm: Holm's adjustment of each kind of p over every
    row of all of them (one family), NaN (no test) left out of m."""
    adjusted = {}
    for column in P_COLUMNS:
        ps = [float(p) for t in tables if len(t) for p in t[column]]
        adjusted[column] = holm(ps)
    out, start = [], 0
    for table in tables:
        table = table.copy()
        for column, holm_column in P_COLUMNS.items():
            table[holm_column] = adjusted[column][start : start + len(table)]
        start += len(table)
        out.append(table)
    return tuple(out)


def stars_differ(row: dict) -> bool:
    """Whether the paired t and the signed-rank test disagree on a row's Holm star."""
    return survives(float(row["p_holm"])) != survives(float(row["p_rank_holm"]))


def counts(tables: Sequence[pd.DataFrame]) -> dict[str, int]:
    """How many tests the family holds (rows), how many could be made (a finite p), and how
    many survive Holm under the t and under the signed-rank test."""
    rows = [r for t in tables for r in t.to_dict("records")]
    return {
        "family": len(rows),
        "made": sum(np.isfinite(float(r["p"])) for r in rows),
        "t": sum(survives(float(r["p_holm"])) for r in rows),
        "rank": sum(survives(float(r["p_rank_holm"])) for r in rows),
    }
