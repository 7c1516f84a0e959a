"""Per-trial data written beside a generated page, so that a reader can test every number of
the page again without the trials: one row per trial, with every measure the page tests and
who computed it. The contact ladder's (experiments/report/ladder_data.py), the ablation
table's (experiments/report/ablation_data.py) and the comparison's
(experiments/report/comparison_data.py) are built from these pieces.

Who computed a trial (`WHO`): the machine and commit of its learning (the trial's
provenance.json, one stretch per resume on another machine, "from iteration N") and of its
evaluation (eval.json's `evaluated_on`), as `provenance.describe` writes a machine.

A measure's part is a column named as the ladder names its measures (`column_name`): the
measure's name for its one value, `name:part` for a part of several (the strategy shares'
hand, tool and vocal).
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from typing import IO

import pandas as pd

from experiments.analysis.results import BatchResults
from experiments.analysis.trial_values import VALUE
from experiments.report.measures import Measure
from experiments.trial_dir.provenance import SHORT_FIELDS, describe

WHO = ["computed_on", "computed_commit", "evaluated_on", "evaluated_commit"]
NOT_RECORDED = "not recorded"
# The columns that say which trial a row is, in every group's table (`group_table`).
TRIAL = ["group", "seed", "trial", "grasp"]


def _stretch_text(row: dict) -> str:
    if row["status"] != "recorded":
        return str(row["status"])
    return describe({k: str(row[k]) for k in SHORT_FIELDS})


def who_computed(results: BatchResults) -> pd.DataFrame:
    """Who computed each trial of `results`: columns trial, seed and WHO, one row per trial. A
    trial resumed on other machines names each, "from iteration N"."""
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
                "trial": str(trial["trial"]),
                "seed": int(trial["seed"]),
                "computed_on": "; ".join(stretches) or NOT_RECORDED,
                "computed_commit": "; ".join(commits) or NOT_RECORDED,
                "evaluated_on": "; ".join(_stretch_text(r) for r in evaluated) or NOT_RECORDED,
                "evaluated_commit": "; ".join(
                    str(r["commit"]) for r in evaluated if r["status"] == "recorded"
                )
                or NOT_RECORDED,
            }
        )
    return pd.DataFrame(rows, columns=["trial", "seed", *WHO])


def read_trial_data(source: str | os.PathLike | IO) -> pd.DataFrame:
    """A per-trial data file read back, the columns of who computed each trial (`WHO`) and the
    trial's name as text: a commit of digits alone ("6163356", or "1234e56") would otherwise be
    read as a number, and lose its leading zeros or its letters."""
    return pd.read_csv(source, dtype=dict.fromkeys(["trial", *WHO], str))


def column_name(measure: Measure, part: str) -> str:
    """The column of a measure's part in a per-trial table (module docstring)."""
    return measure.name if part == VALUE else f"{measure.name}:{part}"


def measure_columns(results: BatchResults, measures: Sequence[Measure]) -> pd.DataFrame:
    """Each measure's value per trial of `results`: columns trial, then one per part of each
    measure (`column_name`, the measures' order), one row per trial; empty where a trial has
    no value."""
    out = results.trials[["trial"]].astype(str).reset_index(drop=True)
    for measure in measures:
        values = measure.values(results)
        parts = {part: column_name(measure, part) for part in measure.parts}
        values = values.assign(trial=values["trial"].astype(str))[["trial", *parts]]
        out = out.merge(values.rename(columns=parts), on="trial", how="left", validate="1:1")
    return out


def group_table(results: BatchResults, measures: Sequence[Measure]) -> pd.DataFrame:
    """One row per trial of `results` (trial names unique within it, as in one batch): TRIAL,
    each measure's parts (`measure_columns`), WHO."""
    trials = results.trials[["group", "seed", "trial", "grasp"]].astype({"trial": str})
    table = trials.merge(measure_columns(results, measures), on="trial", validate="1:1")
    who = who_computed(results).drop(columns="seed")
    return table.merge(who, on="trial", validate="1:1").reset_index(drop=True)
