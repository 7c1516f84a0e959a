"""Logs of two trial directories compared: every column but `trial`, the directory's name,
which tells apart trials that are otherwise the same (a run and its killed-and-resumed twin)."""

from __future__ import annotations

import pandas as pd

from experiments.analysis.logs import read_log


def logs_of(trial_dir, kind: str = "iterations") -> pd.DataFrame:
    """A trial's log without the column that names its directory."""
    return read_log(trial_dir, kind).drop(columns="trial", errors="ignore")


def same_logs(a, b) -> None:
    """Both logs of two trial directories are equal, row for row, apart from `trial`."""
    for kind in ("iterations", "words"):
        assert logs_of(a, kind).equals(logs_of(b, kind)), kind
