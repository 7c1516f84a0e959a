"""A trial's logs, read back (experiments/run/trial_files.py says what a row holds)."""

from __future__ import annotations

import os
from pathlib import Path

import pandas as pd

from experiments import storage
from experiments.file_names import LOG_DIR


def read_log(trial_dir: str | os.PathLike, kind: str = "iterations") -> pd.DataFrame:
    """All chunks of one log ('iterations' or 'words') of a trial, in order."""
    chunks = sorted((Path(trial_dir) / LOG_DIR).glob(f"{kind}-*.parquet"))
    if not chunks:
        return pd.DataFrame()
    return pd.concat([storage.read_table(c) for c in chunks], ignore_index=True)
