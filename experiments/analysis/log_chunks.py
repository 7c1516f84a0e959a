"""Where a trial's log chunks lie (experiments/file_names.py names them).

Each kind of log has its own folder, one chunk per checkpoint period:
`log/iterations/chunk-NNNNNNNN.parquet`, `log/words/chunk-NNNNNNNN.parquet`. Trials written
before the kinds had folders hold `log/iterations-NNNNNNNN.parquet` and
`log/words-NNNNNNNN.parquet` side by side; both layouts are read here (a resume moves the old
chunks into the folders: experiments/run/trial_checks.py, `move_old_chunks`). Read-only.
"""

from __future__ import annotations

import os
import re
from pathlib import Path

from experiments import storage
from experiments.file_names import (
    CONFIG_FILE,
    LOG_CHUNK_PREFIX,
    LOG_DIR,
    LOG_KINDS,
    OLD_LOG_CHUNK_PATTERN,
    log_chunk_name,
)

_CHUNK = re.compile(re.escape(LOG_CHUNK_PREFIX) + r"(?P<start>[0-9]{8})\.parquet")
_OLD_CHUNK = re.compile(OLD_LOG_CHUNK_PATTERN)


class DuplicateChunkError(storage.CorruptFileError):
    """A chunk found in both layouts: which one is the trial's cannot be told."""


def check_kind(kind: str) -> None:
    """ValueError (one line) unless `kind` is a kind of log."""
    if kind not in LOG_KINDS:
        raise ValueError(f"unknown log kind {kind!r}: one of {', '.join(LOG_KINDS)}")


def kind_dir(trial_dir: str | os.PathLike, kind: str) -> Path:
    """The folder of one kind of log of a trial."""
    check_kind(kind)
    return Path(trial_dir) / LOG_DIR / kind


def chunk_path(trial_dir: str | os.PathLike, kind: str, start: int) -> Path:
    """Where the chunk of `kind` that starts at iteration `start` is written."""
    return kind_dir(trial_dir, kind) / log_chunk_name(start)


def old_chunks(trial_dir: str | os.PathLike) -> list[tuple[str, int, Path]]:
    """(kind, start, path) of every chunk of the old layout (side by side in log/)."""
    log = Path(trial_dir) / LOG_DIR
    found = []
    for path in sorted(log.glob("*.parquet")):
        match = _OLD_CHUNK.fullmatch(path.name)
        if match is not None:
            found.append((match["kind"], int(match["start"]), path))
    return found


def chunk_paths(trial_dir: str | os.PathLike, kind: str) -> dict[int, Path]:
    """Every chunk of one kind of log, by the iteration it starts at, in order, from both
    layouts. DuplicateChunkError (one line, naming both) for a chunk found in both."""
    chunks: dict[int, Path] = {}
    folder = kind_dir(trial_dir, kind)
    for path in folder.glob("*.parquet"):
        match = _CHUNK.fullmatch(path.name)
        if match is not None:
            chunks[int(match["start"])] = path
    for found_kind, start, path in old_chunks(trial_dir):
        if found_kind != kind:
            continue
        if start in chunks:
            raise DuplicateChunkError(
                f"{chunks[start]} and {path} both hold the {kind} from iteration {start}: keep "
                "the trial's own one (the other may be a stray copy) and remove the other"
            )
        chunks[start] = path
    return dict(sorted(chunks.items()))


def is_trial_dir(directory: str | os.PathLike) -> bool:
    """Whether a folder is a trial directory: `playroom run` writes its config.json and log/
    (experiments/run/trial_files.py). Another tool's folder with a config.json is not one."""
    directory = Path(directory)
    return (directory / CONFIG_FILE).is_file() and (directory / LOG_DIR).is_dir()
