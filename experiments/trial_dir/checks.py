"""Reading a trial directory back only when it is whole, and saying truly what is not.

- The log chunks a checkpoint covers must be present, the trial's own (the identity they
  carry, if they carry one) and hold what their names say: a lost chunk cannot be regenerated
  (except by running the trial again from scratch), so whatever finds one stops, names it, and
  changes nothing. backend.json must be as the trial's manifest recorded it.
- Temporary files of writers killed mid-write are litter, removed by every writer under the
  lock (a resume, an evaluation), never results.
- Logs of the old layout (chunks of both kinds side by side in log/) are read as they are, and
  brought into their kinds' folders by a resume (old_logs.py).
(The checkpoint itself: checkpoint.py.)
"""

from __future__ import annotations

import json
import os
import re
from pathlib import Path

from experiments.trial_dir import manifest, records, storage
from experiments.trial_dir.config_file import identity_text
from experiments.trial_dir.errors import TrialError
from experiments.trial_dir.layout import (
    CHUNK_IDENTITY_KEY,
    LOG_CHUNK_PREFIX,
    LOG_DIR,
    LOG_KINDS,
    LOST_CHUNK_REMEDY,
    OLD_LOG_CHUNK_PATTERN,
    chunk_file,
    kind_folder,
)
from experiments.trial_dir.log_schema import WORDS_LOG_PERIOD

# The names of the chunks of both layouts (layout.py's docstring).
_CHUNK = re.compile(re.escape(LOG_CHUNK_PREFIX) + r"(?P<start>[0-9]{8})\.parquet")
_OLD_CHUNK = re.compile(OLD_LOG_CHUNK_PATTERN)


# Where pandas keeps a table's attrs in the Parquet schema's metadata (to_parquet, read_parquet).
_PANDAS_ATTRS = b"PANDAS_ATTRS"


class DuplicateChunkError(storage.CorruptFileError):
    """A chunk found in both layouts: which one is the trial's cannot be told."""


class ForeignChunkError(storage.CorruptFileError):
    """A chunk that carries another trial's identity than the trial it lies in."""


def chunk_identity(path: Path) -> object:
    """The identity a chunk carries (as written: a dict, unless someone wrote another thing),
    or None for a chunk written before chunks carried one. CorruptFileError if unreadable."""
    import pyarrow.parquet as pq  # imported where used, as storage.py does

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
    old = old_chunks(trial_dir)
    chunks: dict[int, Path] = {}
    folder = Path(trial_dir) / kind_folder(kind)
    for path in folder.glob("*.parquet"):
        match = _CHUNK.fullmatch(path.name)
        if match is not None:
            chunks[int(match["start"])] = path
    for found_kind, start, path in old:
        if found_kind != kind:
            continue
        if start in chunks:
            raise DuplicateChunkError(
                f"{chunks[start]} and {path} both hold the {kind} from iteration {start}: keep "
                "the trial's own one (the other may be a stray copy) and remove the other"
            )
        chunks[start] = path
    return dict(sorted(chunks.items()))


def check_files(
    trial_dir: Path, meta: dict, identity: dict, recorded: manifest.Manifest | None
) -> None:
    """TrialError unless the logs and backend.json of the trial whose checkpoint has metadata
    `meta` are whole and as its manifest (`recorded`, as the checkpoint's restore read it: None
    for a trial from before manifests) recorded them, those of the trial of `identity`
    (config_file.trial_identity). The memory segments are checked when the checkpoint is
    restored."""
    check_logs(trial_dir, int(meta["iteration"]), identity, recorded)
    if recorded is not None:
        _check_records(trial_dir, recorded)


def recorded_manifest(trial_dir: Path, meta: dict) -> manifest.Manifest | None:
    """The manifest of the checkpoint of metadata `meta`, for a reader that restores nothing
    (a batch's check of what it may skip); TrialError (one line) if it cannot vouch for
    anything."""
    try:
        return manifest.read_manifest(trial_dir, meta)
    except storage.CorruptFileError as exc:
        raise TrialError(_first_line(exc)) from None


def _check_records(trial_dir: Path, recorded: manifest.Manifest) -> None:
    """TrialError unless every record the trial recorded is as recorded (records.py)."""
    try:
        records.check_recorded(trial_dir, recorded)
    except storage.CorruptFileError as exc:
        raise TrialError(str(exc)) from None


def listed_chunks(trial_dir: Path) -> dict[str, dict[int, Path]]:
    """The chunks of every kind of log, of both layouts (layout.py), by kind and start;
    TrialError for a chunk found in both."""
    try:
        return {kind: chunk_paths(trial_dir, kind) for kind in LOG_KINDS}
    except DuplicateChunkError as exc:
        raise TrialError(f"{exc}; nothing was changed") from None


def check_logs(
    trial_dir: str | os.PathLike,
    iteration: int,
    identity: dict,
    recorded: manifest.Manifest | None = None,
    listed: dict[str, dict[int, Path]] | None = None,
) -> None:
    """TrialError naming the first log chunk, of those a checkpoint at `iteration` covers, that
    is missing, unreadable, of another trial than `identity` (config_file.trial_identity),
    not as the checkpoint's manifest (`recorded`, None for a trial from before manifests)
    recorded it, not recorded there, or holds other rows than its name and period say: the
    iterations chunks hold 0 to `iteration` - 1 without a gap, each words chunk the multiples of
    WORDS_LOG_PERIOD its iterations chunk reaches. Chunks starting at `iteration` or later are
    work past the checkpoint (a resume rewrites them) and are not looked at. Chunks of both
    layouts (log/iterations/ and log/words/, or side by side in log/) are read: those `listed`
    by kind (`listed_chunks`), or listed here."""
    trial_dir = Path(trial_dir)
    own = identity
    listed = listed_chunks(trial_dir) if listed is None else listed
    found = {kind: {s: p for s, p in listed[kind].items() if s < iteration} for kind in LOG_KINDS}
    if recorded is not None:
        stray = [p for kind in LOG_KINDS for p in found[kind].values() if p not in recorded]
        if stray:
            raise TrialError(_lost(f"{stray[0]} is not among the files the trial recorded"))
    start = 0
    while start < iteration:
        if start not in found["iterations"]:
            path = trial_dir / chunk_file("iterations", start)
            end = min((s for s in found["iterations"] if s > start), default=iteration)
            raise TrialError(_lost(f"{path} is missing (iterations {start} to {end - 1})"))
        path = found["iterations"][start]
        end = start + _check_rows(
            path, range(start, iteration), (trial_dir, own), recorded, whole=False
        )
        # The words rows this period reached: the multiples of the period in (start, end].
        reached = range(
            (start // WORDS_LOG_PERIOD + 1) * WORDS_LOG_PERIOD, end + 1, WORDS_LOG_PERIOD
        )
        words = found["words"].pop(start, trial_dir / chunk_file("words", start))
        if reached and not words.exists():
            raise TrialError(_lost(f"{words} is missing (words at {reached[0]} to {reached[-1]})"))
        if words.exists():
            _check_rows(words, reached, (trial_dir, own), recorded, whole=True)
        start = end
    for words in found["words"].values():
        raise TrialError(_lost(f"{words} starts where no iterations chunk starts"))


def _check_rows(
    path: Path,
    expected: range,
    trial: tuple[Path, dict],
    recorded: manifest.Manifest | None,
    whole: bool,
) -> int:
    """The number of rows of a log chunk of `trial` (its directory and identity), whose
    iterations must be the first of `expected` (all of them if `whole`), and whose bytes must be
    those the trial's manifest recorded (if it has one); TrialError naming the chunk
    otherwise."""
    try:
        data = path.read_bytes()
        check_chunk(path, trial[1], trial[0])  # first: it names a foreign chunk as such
        if recorded is not None:
            recorded.verify(path, data, "")
        rows = storage.read_column(path, "iteration", data)
    except (ForeignChunkError, manifest.DamagedFileError) as exc:
        raise TrialError(_lost(str(exc).removesuffix(": "))) from None
    except storage.CorruptFileError as exc:
        raise TrialError(_lost(_first_line(exc))) from None
    if not rows or rows != list(expected[: len(rows)]) or (whole and len(rows) != len(expected)):
        wanted = f"iterations {expected[0]} on" if expected else "no rows"
        raise TrialError(_lost(f"{path} does not hold what its name says ({wanted})"))
    return len(rows)


def _first_line(exc: Exception) -> str:
    return str(exc).strip().splitlines()[0] if str(exc).strip() else type(exc).__name__


def _lost(problem: str) -> str:
    """One line: a log chunk that is not whole (`problem` names it), and the only ways back."""
    return f"{problem}: {LOST_CHUNK_REMEDY}; nothing was changed"
