"""The comparison's per-trial data, written beside its page (`comparison-trials.csv`) so that a
reader can test every number of its table of differences again without the trials: one row
per trial of each side, with its batch, group (the side, as the page names it), seed, name and
grasp, every part of every measure the table shows (experiments/report/measures.py; a column
per part, named as trial_data.column_name names it), and who computed it
(experiments/report/trial_data.py: the machine and commit of the learning and of the
evaluation, as ladder-trials.csv records them).

The sides pair by seed where they hold the same seeds (the page's tests then pair them), and
otherwise do not (experiments/report/differences.py)."""

from __future__ import annotations

import pandas as pd

from experiments.analysis.results import BatchResults
from experiments.report.differences import Evaluated
from experiments.report.trial_data import group_table

FILE = "comparison-trials.csv"


def trial_table(evaluated: list[Evaluated], a: BatchResults, b: BatchResults) -> pd.DataFrame:
    """Both sides' trials (`a`, `b`: one group each), side A first: batch, trial_data.TRIAL,
    each evaluated measure's parts, trial_data.WHO."""
    measures = [e.measure for e in evaluated]
    sides = [group_table(side, measures).assign(batch=side.batch_dir.name) for side in (a, b)]
    table = pd.concat(sides, ignore_index=True)
    return table[["batch", *(c for c in table.columns if c != "batch")]]
