"""A trial's logs, or a batch's, read back into one pandas DataFrame.

    from experiments.analysis.logs import read_log, read_batch_logs
    log = read_log("runs/demo/kinematic-random-seed0000")            # one row per iteration
    words = read_batch_logs("runs/demo", kind="words")               # every trial of a batch

What the logs hold, column by column: experiments/log_schema.py; where their chunks lie:
experiments/log_layout.py; the writer (experiments/run/) writes by both. A trial written before
a column existed reads it as the schema declares (missing, for what it did not record). Every
row carries its source (`trial`, `seed`, `backend`, `voice`), so that rows of several trials
keep apart; every chunk its trial's identity, so that a chunk copied from another trial is
refused. Each kind also lies in its own folder (`TRIAL/log/iterations/`, `TRIAL/log/words/`),
so `pd.read_parquet("TRIAL/log/iterations")` reads exactly one kind (in the order of its
chunks' names, which is the iterations' order).
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from pathlib import Path

import pandas as pd

from experiments import storage
from experiments.analysis.finished import unfinished_trials, warn_unfinished
from experiments.config_file import with_added_settings
from experiments.file_names import CONFIG_FILE
from experiments.log_layout import (
    check_chunk,
    check_kind,
    chunk_identity,
    chunk_paths,
    is_trial_dir,
    source_of,
    trial_identity,
)
from experiments.log_schema import SOURCE_COLUMNS, upgraded


def read_log(
    trial_dir: str | os.PathLike, kind: str = "iterations", columns: Sequence[str] | None = None
) -> pd.DataFrame:
    """All chunks of one log ('iterations' or 'words') of a trial, in order, each row with its
    source columns (filled from config.json for logs written before rows carried them). An
    empty DataFrame if the trial has no chunk of that kind yet. storage.CorruptFileError for a
    chunk that cannot be read. `columns`: only those (of them, the ones the log has or the schema
    declares) beside the source columns; a log's 47 columns take twice as long to read as the
    report's 10. Columns the trial's chunks lack are added as experiments/log_schema.py declares
    (`upgraded`: missing, where the trial did not record them).
    A chunk that carries another trial's identity than config.json's (or, without one, than
    the other chunks') is a storage.CorruptFileError too, naming it and both identities."""
    check_kind(kind)
    chunks = chunk_paths(trial_dir, kind)
    if not chunks:
        return pd.DataFrame()
    config_path = Path(trial_dir) / CONFIG_FILE
    config = with_added_settings(storage.read_json(config_path)) if config_path.exists() else None
    own = _identity_of(config)
    wanted = None if columns is None else [*SOURCE_COLUMNS, *columns]
    frames = []
    for chunk in chunks.values():
        if own is None:  # without a config.json, the first chunk's identity is the trial's
            found = chunk_identity(chunk)
            own = found if isinstance(found, dict) else None
        if own is not None:
            check_chunk(chunk, own, trial_dir)
        frames.append(storage.read_table(chunk, wanted))
    frame = pd.concat(frames, ignore_index=True)
    frame = upgraded(frame, kind, columns)  # an older trial's chunks lack newer columns
    missing = [c for c in SOURCE_COLUMNS if c not in frame.columns]
    if missing and config is not None:
        source = source_of(trial_dir, config)
        for position, column in enumerate(SOURCE_COLUMNS):
            if column in missing:
                frame.insert(position, column, source[column])
    return frame


def _identity_of(config: dict | None) -> dict | None:
    """The identity of the trial of a config.json, None without one that names a seed."""
    try:
        return None if config is None else trial_identity(config)
    except (KeyError, TypeError):  # edited by hand: the rows say what they are
        return None


def trial_dirs(batch_dir: str | os.PathLike) -> list[Path]:
    """The trial directories of a batch directory, by name."""
    batch_dir = Path(batch_dir)
    if not batch_dir.is_dir():
        raise ValueError(f"{batch_dir} is not a directory")
    return sorted(d for d in batch_dir.iterdir() if d.is_dir() and is_trial_dir(d))


def read_batch_logs(
    batch_dir: str | os.PathLike, kind: str = "iterations", *, include_incomplete: bool = False
) -> pd.DataFrame:
    """One log ('iterations' or 'words') of every trial of a batch directory in one DataFrame,
    trial after trial (by directory name), each row with its source columns (trial, seed,
    backend, voice). ValueError (one line) for a folder that holds no trial directory.
    Trials that have not run to their end (a batch still running) are named in an
    `IncompleteTrialsWarning` and left out unless `include_incomplete`
    (experiments/analysis/finished.py)."""
    check_kind(kind)
    dirs = trial_dirs(batch_dir)
    if not dirs:
        raise ValueError(
            f"no trial directories in {batch_dir}: a batch directory holds one folder per trial "
            "(its config.json and log/), as `playroom batch --out DIR` writes them"
        )
    incomplete = unfinished_trials(dirs)
    if incomplete:
        warn_unfinished(batch_dir, incomplete, kept=include_incomplete)
        dirs = dirs if include_incomplete else [d for d in dirs if d not in incomplete]
    frames = [frame for frame in (read_log(d, kind) for d in dirs) if not frame.empty]
    return pd.concat(frames, ignore_index=True) if frames else pd.DataFrame()
