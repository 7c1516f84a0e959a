"""A trial's logs, or a batch's, read back into one pandas DataFrame.

    from experiments.analysis.logs import read_log, read_batch_logs
    log = read_log("runs/demo/kinematic-random-seed0000")            # one row per iteration
    words = read_batch_logs("runs/demo", kind="words")               # every trial of a batch

What the logs hold, column by column: experiments/trial_dir/log_schema.py; where their chunks lie:
experiments/trial_dir/layout.py; the writer (experiments/run/) writes by both. A trial written
before a column existed reads it as the schema declares (missing, for what it did not record). Every
row carries its source (`trial`, `seed`, `backend`, `voice`), so that rows of several trials keep
apart; every chunk its trial's identity, so that a chunk copied from another trial is refused. Each
kind also lies in its own folder (`TRIAL/log/iterations/`, `TRIAL/log/words/`), so
`pd.read_parquet("TRIAL/log/iterations")` reads exactly one kind (in the order of its chunks' names,
which is the iterations' order).
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from pathlib import Path

import pandas as pd

from experiments.analysis.batch_checks import check_batch
from experiments.analysis.finished import unfinished_trials, warn_unfinished
from experiments.trial_dir.reading import check_kind, open_for_reading, trials_in, warn_unchecked


def read_log(
    trial_dir: str | os.PathLike, kind: str = "iterations", columns: Sequence[str] | None = None
) -> pd.DataFrame:
    """All chunks of one log ('iterations' or 'words') of a trial, in order, up to its newest
    checkpoint, each row with its source columns (filled from config.json for logs written
    before rows carried them). An empty DataFrame if the trial has no chunk of that kind yet.
    `columns`: only those (of them, the ones the log has or the schema declares) beside the
    source columns; a log's 47 columns take twice as long to read as the report's 10. Columns
    the trial's chunks lack are added as experiments/trial_dir/log_schema.py declares (`upgraded`:
    missing, where the trial did not record them).

    Every chunk is checked before it is read: against the manifest of the trial's newest
    checkpoint (experiments/trial_dir/manifest.py: missing, damaged, replaced or stray chunks are a
    manifest.DamagedFileError naming the chunk), and by the identity it carries (a chunk of
    another trial is a ForeignChunkError); both are storage.CorruptFileError, one line. A
    chunk past the newest checkpoint is a running trial's work in progress, not yet vouched
    for: left out. A trial written before manifests is read unchecked, with an
    UncheckedTrialWarning."""
    frame, checked = open_for_reading(trial_dir).log(kind, columns)
    if not checked:
        warn_unchecked(trial_dir)
    return frame


def trial_dirs(batch_dir: str | os.PathLike) -> list[Path]:
    """The trial directories of a batch directory, by name."""
    batch_dir = Path(batch_dir)
    if not batch_dir.is_dir():
        raise ValueError(f"{batch_dir} is not a directory")
    return trials_in(batch_dir)


def read_batch_logs(
    batch_dir: str | os.PathLike, kind: str = "iterations", *, include_incomplete: bool = False
) -> pd.DataFrame:
    """One log ('iterations' or 'words') of every trial of a batch directory in one DataFrame,
    trial after trial (by directory name), each row with its source columns (trial, seed,
    backend, voice). ValueError (one line) for a folder that holds no trial directory.
    Trials that have not run to their end (a batch still running) are named in an
    `IncompleteTrialsWarning` and left out unless `include_incomplete`
    (experiments/analysis/finished.py). The batch is checked as `playroom report` checks it
    (experiments/analysis/batch_checks.py: BatchMismatch, a ValueError, for two copies of a
    trial or a trial of other settings), and every chunk as `read_log` checks it; trials
    written before manifests are named in one UncheckedTrialWarning."""
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
    configs = [open_for_reading(d).config() for d in dirs]
    check_batch(Path(batch_dir), dirs, configs, frozenset(incomplete))
    frames, unchecked = [], []
    for d in dirs:
        frame, checked = open_for_reading(d).log(kind, None)
        unchecked += [] if checked else [d.name]
        frames += [] if frame.empty else [frame]
    if unchecked:
        warn_unchecked(f"{len(unchecked)} trial(s) of {batch_dir} ({unchecked[0]}, ...)")
    return pd.concat(frames, ignore_index=True) if frames else pd.DataFrame()
