"""The ablation table's per-trial data, written beside it (`ablations-trials.csv`) so that a
reader can test every number of the table again without the trials: one row per trial of each
row of the table (the baseline's trials on the seeds the ablations hold, then each ablation's),
with the row's label as the table shows it, whether it is the baseline, its batch, the trial's
group, seed, name and grasp, every measure the table tests (its `in_ablations` measures of the
registry, one column each) and who computed it (experiments/report/trial_data.py: the machine
and commit of the learning and of the evaluation, as ladder-trials.csv records them).

A row's difference is its trials' values minus the baseline's trials of the same group, seed
by seed; a gap measure's values are also tested against 0 (experiments/report/ablation_tests.py).
"""

from __future__ import annotations

import pandas as pd

from experiments.analysis.results import BatchResults
from experiments.report.measures import Measure
from experiments.report.trial_data import group_table

FILE = "ablations-trials.csv"
# The columns that say which row of the table a trial belongs to, before trial_data.TRIAL.
ROW = ["row", "baseline", "batch"]


def row_trials(
    results: BatchResults, label: str, baseline: bool, measures: tuple[Measure, ...]
) -> pd.DataFrame:
    """The trials of one row of the table (`results`: one group, the row's seeds): ROW,
    trial_data.TRIAL, each measure, trial_data.WHO."""
    table = group_table(results, measures)
    header = pd.DataFrame(
        {"row": label, "baseline": baseline, "batch": results.batch_dir.name}, index=table.index
    )
    return pd.concat([header, table], axis=1)


def trial_table(rows: list[pd.DataFrame]) -> pd.DataFrame:
    """Every row's trials (`row_trials`), in the table's order."""
    return pd.concat(rows, ignore_index=True)
