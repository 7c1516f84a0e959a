"""The contact ladder's per-trial data, written beside its page (`ladder-trials.csv`) so that a
reader can test every number of the page again without the trials: one row per trial and the
world it was tested in (its own, or an eval world), with the rung, the seed, every measure the
page tests (a column per headline measure's key; empty where that world did not measure it:
the eval worlds' rows hold competence only), and who computed it: the machine and commit of the
learning (the trial's provenance.json, one stretch per resume on another machine) and of that
evaluation (its eval.json's `evaluated_on`): experiments/report/trial_data.py, which the other
pages' per-trial data share.

`trial_table` writes the table from `ladder.read_ladder`'s values; `values_from_trial_table`
reads it back into those values, the long table every test of the page is computed from.
"""

from __future__ import annotations

import pandas as pd

from experiments.analysis.results import BatchResults
from experiments.report.trial_data import WHO, who_computed

FILE = "ladder-trials.csv"
KEYS = ["rung", "tested", "seed", "trial"]


def provenance(results: BatchResults, rung: str, tested: str) -> pd.DataFrame:
    """Who computed each trial of `results` (one rung, tested in `tested`): columns KEYS and
    WHO, one row per trial (trial_data.who_computed)."""
    table = who_computed(results).assign(rung=rung, tested=tested)
    return table[KEYS + WHO]


def trial_table(values: pd.DataFrame, where: pd.DataFrame, keys: list[str]) -> pd.DataFrame:
    """One row per trial and world: KEYS, each measure of `keys` (the page's order), WHO.
    `values`: ladder.VALUE_COLUMNS rows; `where`: `provenance`'s rows of every rung and world."""
    wide = values.pivot(index=["rung", "tested", "seed"], columns="key", values="value")
    wide = wide.reindex(columns=[k for k in keys if k in wide.columns]).reset_index()
    table = where.merge(wide, on=["rung", "tested", "seed"], how="outer", validate="one_to_one")
    measures = [k for k in keys if k in table.columns]
    return table[[*KEYS, *measures, *WHO]]


def values_from_trial_table(table: pd.DataFrame) -> pd.DataFrame:
    """`trial_table`'s rows back into ladder.VALUE_COLUMNS rows (rung, tested, seed, key,
    value), an empty cell (a measure that world did not measure) left out."""
    measures = [c for c in table.columns if c not in KEYS + WHO]
    long = table.melt(id_vars=["rung", "tested", "seed"], value_vars=measures, var_name="key")
    return long.dropna(subset=["value"])[["rung", "tested", "seed", "key", "value"]]
