"""How a trial's logs lie on disk and which trial each chunk is: the one description that the
writer (experiments/run/) writes by and every reader (experiments/analysis/logs.py, a resume's
checks) reads by, below both stages so that neither imports the other for it.

Where the chunks lie (experiments/file_names.py names them). Each kind of log has its own
folder, one chunk per checkpoint period: `log/iterations/chunk-NNNNNNNN.parquet`,
`log/words/chunk-NNNNNNNN.parquet`. Trials written before the kinds had folders hold
`log/iterations-NNNNNNNN.parquet` and `log/words-NNNNNNNN.parquet` side by side; both layouts
are read here (a resume moves the old chunks into the folders: experiments/run/old_logs.py).

Which trial a chunk belongs to. Each chunk carries its trial's identity in its Parquet schema's
metadata, as each checkpoint does in its own (`trial_identity`: the seed and a hash of the
settings that make the trial), so that a chunk copied from another trial is told apart
(`check_chunk`). It is written as the table's `attrs[CHUNK_IDENTITY_KEY]`, which pandas keeps
there (JSON under b"PANDAS_ATTRS") and gives back to a reader of the chunk. Chunks written
before they carried one are taken as their trial's, as they always were.

What the rows hold: experiments/log_schema.py, which declares every column of both kinds once
(its type, meaning, what older trials read as, and the change that added it).

Pure functions of paths and dicts, reading only: no simulator, no learner.
"""

from __future__ import annotations

import hashlib
import json
import os
import re
from pathlib import Path

from experiments import storage
from experiments.config_file import identity_form, with_added_settings
from experiments.file_names import (
    CONFIG_FILE,
    LOG_CHUNK_PREFIX,
    LOG_DIR,
    LOG_KINDS,
    OLD_LOG_CHUNK_PATTERN,
    log_chunk_name,
)
from experiments.log_schema import SOURCE_COLUMNS


def source_of(trial_dir: str | os.PathLike, config: dict) -> dict[str, str | int]:
    """The source columns of a trial's rows (log_schema.SOURCE_COLUMNS), from its directory
    and config (of any version: a trial older than the voice setting ran with VocalTractLab)."""
    trial = with_added_settings(config)["trial"]
    name = Path(trial_dir).resolve().name
    values = (name, int(trial["seed"]), str(trial["grasp"]), str(trial["voice"]))
    return dict(zip(SOURCE_COLUMNS, values, strict=True))


_CHUNK = re.compile(re.escape(LOG_CHUNK_PREFIX) + r"(?P<start>[0-9]{8})\.parquet")
_OLD_CHUNK = re.compile(OLD_LOG_CHUNK_PATTERN)


# The key of a chunk's table attrs that holds its trial's identity, and where pandas keeps a
# table's attrs in the Parquet schema's metadata (DataFrame.to_parquet, read_parquet).
CHUNK_IDENTITY_KEY = "playroom.trial"
_PANDAS_ATTRS = b"PANDAS_ATTRS"
# Settings a resume may change: a trial can be extended to more iterations.
EXTENSIBLE = ("trial.iterations",)
# What an identity leaves out of its trial's config: the settings a resume may change, and the
# package version. The version says which code wrote config.json, not which trial it is; in the
# identity it would orphan every checkpoint at each release (whether a trial may be resumed by
# another version is for the config comparison on resume to say).
_NOT_IDENTITY = (*EXTENSIBLE, "package_version")


# What a user can do about a log chunk that is missing, damaged or foreign: said after it.
LOST_CHUNK_REMEDY = (
    "the logs of a trial cannot be regenerated except by running it again from scratch (into "
    "a new directory, with the settings in its config.json) or restored from a backup"
)


class DuplicateChunkError(storage.CorruptFileError):
    """A chunk found in both layouts: which one is the trial's cannot be told."""


class ForeignChunkError(storage.CorruptFileError):
    """A chunk that carries another trial's identity than the trial it lies in."""


def trial_identity(config: dict) -> dict:
    """What a trial's checkpoints and log chunks carry of it: the seed, and a hash of the
    trial's config without the settings that are not the trial's identity (_NOT_IDENTITY)."""
    kept = identity_form(config)  # a copy, as older trials' configs would read
    for key in _NOT_IDENTITY:
        *parents, last = key.split(".")
        node = kept
        for parent in parents:
            node = node.get(parent, {})
        node.pop(last, None)
    text = json.dumps(kept, sort_keys=True, separators=(",", ":"))
    digest = hashlib.sha256(text.encode()).hexdigest()[:12]
    return {"seed": config["trial"]["seed"], "config": digest}


def identity_text(identity: object) -> str:
    """An identity as messages show it: "seed 5, config 0123456789ab"."""
    found = identity if isinstance(identity, dict) else {}
    return f"seed {found.get('seed', '?')}, config {found.get('config', '?')}"


def chunk_identity(path: Path) -> object:
    """The identity a chunk carries (as written: a dict, unless someone wrote another thing),
    or None for a chunk written before chunks carried one. CorruptFileError if unreadable."""
    import pyarrow.parquet as pq  # imported where used, as experiments/storage.py does

    try:
        metadata = pq.read_schema(path).metadata or {}
    except Exception as exc:  # pyarrow raises several types for damaged files
        raise storage.CorruptFileError(f"{path} is damaged or truncated ({exc})") from None
    try:
        attrs = json.loads(metadata.get(_PANDAS_ATTRS, b"{}"))
    except (UnicodeDecodeError, json.JSONDecodeError):
        return "unreadable"  # not the trial's own writing: never taken as its identity
    return attrs.get(CHUNK_IDENTITY_KEY) if isinstance(attrs, dict) else "unreadable"


def check_chunk(path: Path, own: dict, trial_dir: str | os.PathLike) -> None:
    """ForeignChunkError (one line, naming the chunk and both identities) if the chunk at
    `path` carries another identity than `own`, its trial's; a chunk without one passes."""
    found = chunk_identity(path)
    if found is not None and found != own:
        raise ForeignChunkError(
            f"{path} belongs to another trial ({identity_text(found)}) than {trial_dir} "
            f"({identity_text(own)}); refusing to mix them"
        )


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
