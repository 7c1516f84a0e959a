"""Trials made to look as older versions of the project wrote them, for the tests that check
such trials are still read, resumed and extended (and their evaluations read)."""

from __future__ import annotations

import shutil
from collections.abc import Callable
from pathlib import Path

from experiments.trial_dir import eval_record, storage
from experiments.trial_dir.layout import (
    CHECKPOINT_FILE,
    EVAL_FILE,
    MANIFEST_DIR,
    PREVIOUS_CHECKPOINT_FILE,
    VOCAL_FILE,
)
from experiments.trial_dir.manifest import EVAL_FILES_KEY, MANIFEST_KEY

# What checkpoints recorded of their directory since manifests.
_SINCE_MANIFESTS = (MANIFEST_KEY, "trial_name")


def before_manifests(meta: dict) -> dict:
    """A checkpoint's metadata as written before manifests (and the name a trial was created
    as) were recorded."""
    return {k: v for k, v in meta.items() if k not in _SINCE_MANIFESTS}


def as_before_manifests(trial_dir: Path) -> None:
    """A trial's checkpoints and folder as written before manifests: no manifest named in its
    checkpoints, no manifest/ folder."""
    for name in (CHECKPOINT_FILE, PREVIOUS_CHECKPOINT_FILE):
        if (trial_dir / name).exists():
            arrays, meta = storage.read_arrays(trial_dir / name)
            storage.write_arrays(trial_dir / name, arrays, before_manifests(meta))
    shutil.rmtree(trial_dir / MANIFEST_DIR, ignore_errors=True)


def as_evaluated_before_names_had_toys(trial_dir: Path) -> None:
    """A trial's evaluation as written before its vocal table recorded which toy each name
    names: that table without its `toy` column, and eval.json without the list of its tables'
    sizes and checksums (`EVAL_FILES_KEY`), which evaluations began to write later. Each file
    as that version wrote it: a table edited under an eval.json that lists it is a replaced
    table, which every reader refuses."""
    vocal = storage.read_table(trial_dir / VOCAL_FILE).drop(columns="toy")
    storage.write_bytes(trial_dir / VOCAL_FILE, storage.table_bytes(vocal))
    summary = storage.read_json(trial_dir / EVAL_FILE)
    # Neither its tables' list nor the checksum and trial identity, which came later still.
    for key in (EVAL_FILES_KEY, eval_record.CHECKSUM_KEY, eval_record.IDENTITY_KEY):
        summary.pop(key, None)
    storage.write_json(trial_dir / EVAL_FILE, summary)


def rewritten_evaluation(folder: Path, config: dict, change: Callable[[dict], None]) -> None:
    """The eval.json in `folder` (of the trial whose config.json is `config`) changed by
    `change` and written again as the version that made it would have: intact, with its
    checksum and trial recorded (an evaluation made otherwise, not a damaged one)."""
    summary = eval_record.read_evaluation(folder, config, "")
    change(summary)
    storage.write_bytes(folder / EVAL_FILE, eval_record.evaluation_json(summary, config))


def as_before_eval_checksums(folder: Path) -> None:
    """The eval.json in `folder` as written before it recorded its checksum and its trial."""
    summary = storage.read_json(folder / EVAL_FILE)
    for key in (eval_record.CHECKSUM_KEY, eval_record.IDENTITY_KEY):
        summary.pop(key)
    storage.write_json(folder / EVAL_FILE, summary)
