"""Trials made to look as older versions of the project wrote them, for the tests that check
such trials are still read, resumed and extended."""

from __future__ import annotations

import shutil
from pathlib import Path

from experiments import storage
from experiments.file_names import (
    CHECKPOINT_FILE,
    EVAL_FILE,
    MANIFEST_DIR,
    PREVIOUS_CHECKPOINT_FILE,
    VOCAL_FILE,
)
from experiments.manifest import EVAL_FILES_KEY, MANIFEST_KEY

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
    del summary[EVAL_FILES_KEY]
    storage.write_json(trial_dir / EVAL_FILE, summary)
