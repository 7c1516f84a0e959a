"""The contact ladder's per-trial data, written beside its page (`ladder-trials.csv`) so that a
reader can test every number of the page again without the trials: one row per trial and the
world it was tested in (its own, or an eval world), with the rung, the seed, every measure the
page tests (a column per headline measure's key; empty where that world did not measure it:
the eval worlds' rows hold competence only), and who computed it: the machine and commit of the
learning (the trial's provenance.json, one stretch per resume on another machine) and of that
evaluation (its eval.json's `evaluated_on`).

`trial_table` writes the table from `ladder.read_ladder`'s values; `values_from_trial_table`
reads it back into those values, the long table every test of the page is computed from.
"""

from __future__ import annotations

import pandas as pd

from experiments.analysis.results import BatchResults
from experiments.provenance import SHORT_FIELDS, describe

FILE = "ladder-trials.csv"
KEYS = ["rung", "tested", "seed", "trial"]
WHO = ["computed_on", "computed_commit", "evaluated_on", "evaluated_commit"]
NOT_RECORDED = "not recorded"


def _stretch_text(row: dict) -> str:
    if row["status"] != "recorded":
        return str(row["status"])
    return describe({k: str(row[k]) for k in SHORT_FIELDS})


def provenance(results: BatchResults, rung: str, tested: str) -> pd.DataFrame:
    """Who computed each trial of `results` (one rung, tested in `tested`): columns KEYS and
    WHO, one row per trial. A trial resumed on other machines names each, "from iteration N"."""
    where = results.provenance
    rows = []
    for trial in results.trials[["trial", "seed"]].to_dict("records"):
        mine = where[where["trial"] == trial["trial"]] if "trial" in where else where.iloc[:0]
        learned = mine[mine["role"] == "computed"].to_dict("records") if len(mine) else []
        evaluated = mine[mine["role"] == "evaluated"].to_dict("records") if len(mine) else []
        stretches = [f"{_stretch_text(r)} from iteration {r['from_iteration']}" for r in learned]
        commits = sorted({str(r["commit"]) for r in learned if r["status"] == "recorded"})
        rows.append(
            {
                "rung": rung,
                "tested": tested,
                "seed": int(trial["seed"]),
                "trial": str(trial["trial"]),
                "computed_on": "; ".join(stretches) or NOT_RECORDED,
                "computed_commit": "; ".join(commits) or NOT_RECORDED,
                "evaluated_on": "; ".join(_stretch_text(r) for r in evaluated) or NOT_RECORDED,
                "evaluated_commit": "; ".join(
                    str(r["commit"]) for r in evaluated if r["status"] == "recorded"
                )
                or NOT_RECORDED,
            }
        )
    return pd.DataFrame(rows, columns=KEYS + WHO)


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
