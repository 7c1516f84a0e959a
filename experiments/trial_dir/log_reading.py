"""A trial's log read back whole and checked: every chunk of one kind, up to the trial's newest
checkpoint, checked against its manifest and by the identity it carries, joined in order and
brought to the newest columns (log_schema.py); the rows of a trial from before manifests read
as they lie, and said so.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import pandas as pd

from experiments.trial_dir import manifest, storage
from experiments.trial_dir.checks import check_chunk, chunk_identity, chunk_paths
from experiments.trial_dir.config_file import (
    UnknownSettingError,
    check_known,
    source_of,
    trial_identity,
    with_added_settings,
)
from experiments.trial_dir.layout import CONFIG_FILE, LOST_CHUNK_REMEDY, check_kind, kind_folder
from experiments.trial_dir.log_schema import SOURCE_COLUMNS, upgraded


def read_log_checked(
    trial_dir: Path, kind: str, columns: Sequence[str] | None
) -> tuple[pd.DataFrame, bool]:
    """All chunks of one log ('iterations' or 'words') of a trial, in order, up to its newest
    checkpoint, each row with its source columns (filled from config.json for logs written
    before rows carried them), and whether the trial's manifest checked them (False: a trial
    written before manifests, read unchecked). An empty DataFrame if the trial has no chunk of
    that kind yet. `columns`: only those (of them, the ones the log has or the schema declares)
    beside the source columns. Columns the trial's chunks lack are added as log_schema.py
    declares (`upgraded`: missing, where the trial did not record them).

    Every chunk is checked before it is read: against the manifest of the trial's newest
    checkpoint (manifest.py: missing, damaged, replaced or stray chunks are a
    manifest.DamagedFileError naming the chunk), and by the identity it carries (a chunk of
    another trial is a ForeignChunkError); both are storage.CorruptFileError, one line. A
    chunk past the newest checkpoint is a running trial's work in progress, not yet vouched
    for: left out."""
    check_kind(kind)
    recorded = manifest.trial_manifest(trial_dir, warn=False)
    chunks = chunk_paths(trial_dir, kind)
    if recorded is not None:
        chunks = _vouched_for(trial_dir, kind, chunks, recorded)
    if not chunks:
        return pd.DataFrame(), recorded is not None
    config_path = trial_dir / CONFIG_FILE
    config = with_added_settings(storage.read_json(config_path)) if config_path.exists() else None
    if config is not None:
        try:
            check_known(config, config_path)
        except UnknownSettingError as exc:
            raise storage.CorruptFileError(str(exc)) from None
    own = _identity_of(config)
    wanted = None if columns is None else [*SOURCE_COLUMNS, *columns]
    frames = []
    for chunk in chunks.values():
        data = chunk.read_bytes()
        if own is None:  # without a config.json, the first chunk's identity is the trial's
            found = chunk_identity(chunk)
            own = found if isinstance(found, dict) else None
        if own is not None:
            check_chunk(chunk, own, trial_dir)
        if recorded is not None:
            recorded.verify(chunk, data, LOST_CHUNK_REMEDY)
        frames.append(storage.read_table(chunk, wanted, data))
    frame = pd.concat(frames, ignore_index=True)
    frame = upgraded(frame, kind, columns)  # an older trial's chunks lack newer columns
    missing = [c for c in SOURCE_COLUMNS if c not in frame.columns]
    if missing and config is not None:
        source = source_of(trial_dir, config)
        for position, column in enumerate(SOURCE_COLUMNS):
            if column in missing:
                frame.insert(position, column, source[column])
    return frame, recorded is not None


def _vouched_for(
    trial_dir: Path, kind: str, chunks: dict[int, Path], recorded: manifest.Manifest
) -> dict[int, Path]:
    """The chunks the trial's newest checkpoint vouches for; manifest.DamagedFileError for one
    it recorded that is missing, or one before it that it did not record (a stray copy)."""
    folder = Path(trial_dir) / kind_folder(kind)
    for name in recorded.files:
        path = trial_dir / name
        if path.parent == folder and not path.exists():
            raise manifest.DamagedFileError(f"{path} is missing: {LOST_CHUNK_REMEDY}")
    kept = {}
    for start, path in chunks.items():
        if path in recorded:
            kept[start] = path
        elif start < recorded.iteration:
            raise manifest.DamagedFileError(
                f"{path} is not among the files the trial's checkpoint recorded (a stray or "
                f"foreign file?): {LOST_CHUNK_REMEDY}"
            )
    return kept


def _identity_of(config: dict | None) -> dict | None:
    """The identity of the trial of a config.json, None without one that names a seed."""
    try:
        return None if config is None else trial_identity(config)
    except (KeyError, TypeError):  # edited by hand: the rows say what they are
        return None
