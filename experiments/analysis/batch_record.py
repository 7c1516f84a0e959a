"""What a batch directory records of the batch that wrote it (batch.json, written by
`playroom batch`): here, the size of the study's random reference its reports play, which the
batch's profile sets (experiments/batches/profiles/*.json, "study_reference_commands")."""

from __future__ import annotations

import os
from collections.abc import Iterable
from pathlib import Path

from experiments import storage
from experiments.file_names import BATCH_FILE


def recorded_reference_commands(batch_dirs: Iterable[str | os.PathLike]) -> int | None:
    """The largest study reference size (random commands per ring) the batches record, so that
    a page setting a small batch beside a large one measures both as the large one asks; None
    where none records one (a batch written before batch.json: the study's size applies)."""
    sizes = []
    for batch_dir in batch_dirs:
        path = Path(batch_dir) / BATCH_FILE
        try:
            record = storage.read_json(path) if path.is_file() else None
        except (storage.CorruptFileError, OSError):
            record = None  # a damaged record is no record: the study's size applies
        size = record.get("study_reference_commands") if isinstance(record, dict) else None
        if isinstance(size, int) and not isinstance(size, bool) and size > 0:
            sizes.append(size)
    return max(sizes, default=None)
