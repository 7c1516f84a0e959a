"""Trials of the old log layout brought into the folders, on resume.

Trials written before each kind of log had its folder hold `log/iterations-NNNNNNNN.parquet`
and `log/words-NNNNNNNN.parquet` side by side, without the columns rows carry since (their
source: trial, seed, backend, voice; the learner's goal, outcome and interests). Every reader
reads them as they are (experiments/trial_dir/layout.py); a resume, which writes new chunks
into the folders, first brings the old ones there too, so that a kind's folder reads as one
table (`pd.read_parquet("TRIAL/log/iterations")`).

Each chunk is brought over in two atomic steps: its missing columns are added in place (the
source from config.json, NaN for the learner's columns, which were not logged then; rows and
existing columns unchanged), then it is renamed into its folder. A resume killed at any moment
leaves every chunk whole in one layout or the other, which both readers read, and the next
resume finishes the move.
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from experiments.trial_dir import storage
from experiments.trial_dir.layout import chunk_file
from experiments.trial_dir.log_schema import LEARNER_COLUMNS, LEARNER_DTYPE, SOURCE_COLUMNS


def move_old_chunks(
    trial_dir: Path, source: dict, listed: dict[str, dict[int, Path]]
) -> tuple[int, dict[str, dict[int, Path]]]:
    """Bring the chunks of the old layout among those `listed` (by kind and start, of both
    layouts: checks.listed_chunks) into their kinds' folders (module docstring), the source
    columns their rows lack set to `source` (config_file.source_of); returns how many were
    moved, and the listing with each chunk where it lies now. Called under the directory's
    lock, after the logs were checked (a chunk found in both layouts stops that check)."""
    moved = 0
    now: dict[str, dict[int, Path]] = {}
    for kind, chunks in listed.items():
        now[kind] = {}
        for start, path in chunks.items():
            target = Path(trial_dir) / chunk_file(kind, start)
            now[kind][start] = target
            if path != target:
                _move(kind, path, target, source)
                moved += 1
    return moved, now


def _move(kind: str, path: Path, target: Path, source: dict) -> None:
    """One chunk of the old layout brought to `target`, in its kind's folder."""
    target.parent.mkdir(exist_ok=True)
    try:
        table = storage.read_table(path)
    except storage.CorruptFileError:
        # Past the checkpoint (the check read every chunk before it): the resume deletes it
        # and writes it again.
        os.replace(path, target)
        return
    added = False
    for position, column in enumerate(SOURCE_COLUMNS):
        if column not in table.columns:
            table.insert(position, column, source[column])
            added = True
    if kind == "iterations":
        for column in LEARNER_COLUMNS:
            if column not in table.columns:
                table[column] = np.full(len(table), np.nan, dtype=LEARNER_DTYPE)
                added = True
    if added:
        storage.write_table(path, table, plain=LEARNER_COLUMNS if kind == "iterations" else ())
    os.replace(path, target)
