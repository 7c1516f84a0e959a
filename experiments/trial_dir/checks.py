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

import os
from pathlib import Path

from experiments.trial_dir import manifest, storage
from experiments.trial_dir.config_file import trial_identity, with_added_settings
from experiments.trial_dir.errors import TrialError
from experiments.trial_dir.layout import (
    BACKEND_FILE,
    CONFIG_FILE,
    LOG_KINDS,
    LOST_CHUNK_REMEDY,
    DuplicateChunkError,
    ForeignChunkError,
    check_chunk,
    chunk_path,
    chunk_paths,
)
from experiments.trial_dir.log_schema import WORDS_LOG_PERIOD


def check_files(trial_dir: Path, meta: dict, config: dict) -> manifest.Manifest | None:
    """TrialError unless the logs and backend.json of the trial whose checkpoint has metadata
    `meta` are whole and as its manifest recorded them (the memory segments are checked when the
    checkpoint is restored); the manifest, None for a trial from before manifests."""
    recorded = recorded_manifest(trial_dir, meta)
    check_logs(trial_dir, int(meta["iteration"]), config, recorded)
    if recorded is not None:
        _check_backend(trial_dir, recorded)
    return recorded


def recorded_manifest(trial_dir: Path, meta: dict) -> manifest.Manifest | None:
    """The manifest of a restored checkpoint (its chain already read once by the restore)."""
    try:
        return manifest.read_manifest(trial_dir, meta)
    except storage.CorruptFileError as exc:
        raise TrialError(_first_line(exc)) from None


def _check_backend(trial_dir: Path, recorded: manifest.Manifest) -> None:
    """TrialError unless backend.json is as the trial recorded it (when it recorded one)."""
    path = trial_dir / BACKEND_FILE
    if path in recorded:
        try:
            recorded.read_bytes(path, f"`playroom run --out {trial_dir} --resume` regenerates it")
        except storage.CorruptFileError as exc:
            raise TrialError(str(exc)) from None


def checked_chunks(trial_dir: Path, kind: str) -> dict[int, Path]:
    """The chunks of one kind of log, of both layouts (layout.py);
    TrialError for a chunk found in both."""
    try:
        return chunk_paths(trial_dir, kind)
    except DuplicateChunkError as exc:
        raise TrialError(f"{exc}; nothing was changed") from None


def check_logs(
    trial_dir: str | os.PathLike,
    iteration: int,
    config: dict | None = None,
    recorded: manifest.Manifest | None = None,
) -> None:
    """TrialError naming the first log chunk, of those a checkpoint at `iteration` covers, that
    is missing, unreadable, of another trial than `config`'s (the trial's config.json if None),
    not as the checkpoint's manifest (`recorded`, None for a trial from before manifests)
    recorded it, not recorded there, or holds other rows than its name and period say: the
    iterations chunks hold 0 to `iteration` - 1 without a gap, each words chunk the multiples of
    WORDS_LOG_PERIOD its iterations chunk reaches. Chunks starting at `iteration` or later are
    work past the checkpoint (a resume rewrites them) and are not looked at. Chunks of both
    layouts (log/iterations/ and log/words/, or side by side in log/) are read."""
    trial_dir = Path(trial_dir)
    if config is None:
        config = with_added_settings(storage.read_json(trial_dir / CONFIG_FILE))
    own = trial_identity(config)
    found = {
        kind: {s: p for s, p in checked_chunks(trial_dir, kind).items() if s < iteration}
        for kind in LOG_KINDS
    }
    if recorded is not None:
        stray = [p for kind in LOG_KINDS for p in found[kind].values() if p not in recorded]
        if stray:
            raise TrialError(_lost(f"{stray[0]} is not among the files the trial recorded"))
    start = 0
    while start < iteration:
        if start not in found["iterations"]:
            path = chunk_path(trial_dir, "iterations", start)
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
        words = found["words"].pop(start, chunk_path(trial_dir, "words", start))
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


def _alive(pid: int) -> bool:
    """Whether a process `pid` runs on this machine."""
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:  # another user's
        return True
    return True


def is_litter(name: str) -> bool:
    """Whether a file named `name` is a temporary file of a writer that no longer runs."""
    pid = storage.temporary_writer(name)
    return pid is not None and not _alive(pid)


def remove_litter(trial_dir: str | os.PathLike) -> list[str]:
    """Remove the temporary files that writers killed mid-write (storage.write_bytes) left in a
    trial directory, wherever they lie in it (its memory/, log/, manifest/, an eval world's
    folder...); returns their paths relative to the directory.

    Called under the directory's lock: every writer of the trial's own files (run, eval, a
    batch task) holds it, so such a file there was left by a dead writer. A live process is
    still spared: a writer that takes no lock (a video rendered into the directory) may own
    it. A spared file is never taken for a result either (experiments/run/trial.py's derived
    files leave temporary files out)."""
    trial_dir = Path(trial_dir)
    removed = []
    for path in sorted(trial_dir.rglob(".*.tmp")):
        if is_litter(path.name):
            path.unlink(missing_ok=True)
            removed.append(path.relative_to(trial_dir).as_posix())
    return removed
