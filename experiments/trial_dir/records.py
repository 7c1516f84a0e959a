"""A trial's records: the small JSON files a run writes of itself (layout.RECORDS, by kind:
backend.json, summary.json), each recorded in the manifest of the checkpoint after it.

- Written: with the checkpoint that records it (`write_new`), or, for a record the run
  computes again whenever it opens (what its backend declares), once (`regenerate`): a record
  lost or damaged since is written again when the run computes exactly the recorded bytes, and
  refused otherwise.
- Checked: every record the manifest holds, whenever a trial is checked whole
  (checks.check_files: the readers that restore a trial, a batch's check of what it may skip),
  and a record when it is read (`read_checked`).

A record a newer version adds is one line of layout.RECORDS and the code that computes it:
nothing here, in the checks or in the readers names one.
"""

from __future__ import annotations

import math
import os
from pathlib import Path
from typing import Any

import numpy as np

from experiments.trial_dir import manifest, storage
from experiments.trial_dir.layout import RECORDS


def record_path(trial_dir: str | os.PathLike, kind: str) -> Path:
    """Where the record of `kind` (a key of layout.RECORDS) lies in a trial directory."""
    return Path(trial_dir) / RECORDS[kind]


def remedy(trial_dir: str | os.PathLike) -> str:
    """What a user can do about a record that is missing or not as recorded."""
    return f"`playroom run --out {trial_dir} --resume` regenerates it"


def write_new(
    trial_dir: str | os.PathLike, kind: str, record: dict, unrecorded: list[Path]
) -> None:
    """Write the record of `kind` and append its path to `unrecorded` (the files the next
    checkpoint's manifest records)."""
    path = record_path(trial_dir, kind)
    storage.write_json(path, record)
    unrecorded.append(path)


def regenerate(
    trial_dir: str | os.PathLike,
    kind: str,
    record: dict,
    recorded: manifest.Manifest | None,
    unrecorded: list[Path],
    computed_from: str,
) -> str | None:
    """Write the record of `kind` unless the trial has one: the first run (or, for a trial
    written before such records, the first resume) writes it and appends its path to
    `unrecorded`. One the trial's manifest (`recorded`) holds but that is lost or damaged is
    written again when `record` (computed from `computed_from`, as messages say it) is exactly
    what was recorded (a line saying so is returned), and refused otherwise
    (manifest.DamagedFileError, one line)."""
    path = record_path(trial_dir, kind)
    data = storage.json_bytes(record)  # as storage.write_json writes it
    if recorded is None or path not in recorded:
        if not path.exists():
            storage.write_bytes(path, data)
        unrecorded.append(path)
        return None
    problem = recorded.problem_with(path)
    if problem is None:
        return None
    if not recorded.holds(path, data):
        raise manifest.DamagedFileError(
            f"{problem}, and {computed_from} now gives another record than the trial wrote "
            f"({record}): it cannot be regenerated; restore it from a backup"
        )
    storage.write_bytes(path, data)
    return f"{problem}: regenerated from {computed_from}, identical to the recorded one"


def check_recorded(trial_dir: str | os.PathLike, recorded: manifest.Manifest) -> None:
    """manifest.DamagedFileError (one line, naming it) for the first record the manifest holds
    that is missing or not as recorded."""
    for kind in RECORDS:
        path = record_path(trial_dir, kind)
        if path in recorded:
            recorded.read_bytes(path, remedy(trial_dir))


def read_checked(trial_dir: str | os.PathLike, kind: str) -> Any | None:
    """The record of `kind`, checked against the trial's manifest; None when its newest
    checkpoint records none (one on disk was written past it, by a run killed before its
    checkpoint). A trial from before manifests: the record as it lies, if there is one.
    storage.CorruptFileError for one that is not JSON or not what the trial recorded
    (manifest.DamagedFileError, saying how to regenerate it)."""
    path = record_path(trial_dir, kind)
    recorded = manifest.trial_manifest(trial_dir, warn=False)
    if recorded is None:
        return storage.read_json(path) if path.exists() else None
    if path not in recorded:
        return None
    return storage.json_from_bytes(recorded.read_bytes(path, remedy(trial_dir)), path)


def summary_record(iteration: int, counts: dict[str, int], best_word_distance: np.ndarray) -> dict:
    """The summary record: where a trial's run ended (its iteration, what it counted, the best
    distance it reached to each of its voice's words, in their order; null for one never
    reached)."""
    return {
        "iteration": int(iteration),
        "counts": {name: int(n) for name, n in counts.items()},
        "best_word_distance": [float(d) if math.isfinite(d) else None for d in best_word_distance],
    }
