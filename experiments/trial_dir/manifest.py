"""What a trial wrote, file by file: every data file's size and SHA-256, recorded with the
checkpoint that covers it, so that a reader tells a damaged, missing or foreign file from a
good one before it computes anything from it.

What is recorded. Every data file of a trial directory but its checkpoints: the log chunks of
both kinds (`log/iterations/chunk-*.parquet`, `log/words/chunk-*.parquet`), the memory
segments (`memory/rows-*.npz`) and the trial's records (`backend.json`, `summary.json`:
layout.RECORDS, records.py). Checkpoints are not listed: an `.npz` is a
zip archive whose every member carries its own CRC-32, which NumPy's reader checks, and the
previous checkpoint is kept beside the newest. config.json is not listed either: a resume
rewrites it when the trial is extended, and its content is checked otherwise (each
checkpoint, chunk and segment carries a hash of it: config_file.py `trial_identity`).
An evaluation's tables are listed in its own eval.json (`EVAL_FILES_KEY`), which is written
after them (storage.py `write_files`) and records its own checksum and trial
(experiments/trial_dir/eval_record.py: written after the last checkpoint, no manifest can list it).

How it is kept: append-only, as the memory is (experiments/trial_dir/memory_segments.py), so that
a checkpoint's cost does not grow with the trial. Each checkpoint writes the entries of the
files written since the checkpoint before it into a small JSON file of its own,
`manifest/files-NNNNNNNN.json` (NNNNNNNN the iteration of the checkpoint), which names the
file before it and its SHA-256; the checkpoint names the newest and its SHA-256 in its
metadata (MANIFEST_KEY). Reading the chain back from the checkpoint checks every link, so the
whole manifest is as trustworthy as the checkpoint that names it. Order on disk, for crash
safety: the period's chunks and segment, then its manifest file, then the checkpoint. A run
killed before the checkpoint leaves a manifest file past the newest checkpoint, which a resume
deletes with the logs past it (`drop_past`) and writes again; a reader never reaches it, as
nothing names it.

Trials written before manifests (their checkpoints name none) are read as before, unchecked,
with one warning (`UncheckedTrialWarning`); the first checkpoint a resume writes records
every data file then present, and the trial is checked from there on.
"""

from __future__ import annotations

import dataclasses
import hashlib
import os
import re
import warnings
from collections.abc import Iterable
from pathlib import Path

from experiments.trial_dir import storage
from experiments.trial_dir.layout import (
    CHECKPOINT_FILE,
    LOG_DIR,
    LOG_KINDS,
    MANIFEST_DIR,
    MEMORY_DIR,
    OLD_LOG_CHUNK_PATTERN,
    PREVIOUS_CHECKPOINT_FILE,
    RECORDS,
    manifest_name,
)

# The checkpoint metadata's entry naming the newest manifest file ({"name", "sha256"}).
MANIFEST_KEY = "manifest"
# eval.json's entry listing the evaluation's tables ({name: [size, sha256]}).
EVAL_FILES_KEY = "files"
_MANIFEST = re.compile(r"files-(?P<iteration>[0-9]{8,})\.json")


class DamagedFileError(storage.CorruptFileError):
    """A data file that is missing, or whose size or checksum is not what the trial's manifest
    recorded (damaged, truncated, or another trial's): one line naming it."""


class UncheckedTrialWarning(UserWarning):
    """A trial written before manifests was read: its files could not be checked."""

    # What the warning says of the trials it names, and what to do.
    what = (
        "written before trials recorded a manifest of their files, read unchecked "
        "(`playroom run --out DIR --resume` with more --iterations records one)"
    )


class UncheckedEvaluationWarning(UncheckedTrialWarning):
    """An evaluation written before eval.json recorded its checksum and its trial was read: it
    could not be checked (experiments/trial_dir/eval_record.py)."""

    what = (
        "evaluated before eval.json recorded its checksum and its trial, read unchecked "
        "(evaluating it again records them: `playroom eval DIR` for a trial)"
    )


@dataclasses.dataclass(frozen=True)
class Entry:
    """One file as recorded: its size in bytes and the SHA-256 of its bytes (hex)."""

    size: int
    sha256: str

    def as_json(self) -> list:
        return [self.size, self.sha256]


def entry_of(data: bytes) -> Entry:
    return Entry(len(data), hashlib.sha256(data).hexdigest())


def relative(trial_dir: Path, path: Path) -> str:
    """How a manifest names a file of a trial directory: its path from there, with '/'."""
    return Path(path).relative_to(trial_dir).as_posix()


def data_files(trial_dir: str | os.PathLike) -> list[Path]:
    """Every data file of a trial directory a manifest records (module docstring), in order:
    what lies there now, recorded or not."""
    trial_dir = Path(trial_dir)
    found = [trial_dir / name for name in RECORDS.values() if (trial_dir / name).is_file()]
    for kind in LOG_KINDS:
        found += sorted((trial_dir / LOG_DIR / kind).glob("chunk-*.parquet"))
    # Chunks of the old layout, side by side in log/ (a resume moves them into the folders).
    old = re.compile(OLD_LOG_CHUNK_PATTERN)
    found += sorted(p for p in (trial_dir / LOG_DIR).glob("*.parquet") if old.fullmatch(p.name))
    found += sorted((trial_dir / MEMORY_DIR).glob("rows-*.npz"))
    return found


@dataclasses.dataclass(frozen=True)
class Manifest:
    """Every file a trial's checkpoint vouches for: relative path -> Entry."""

    trial_dir: Path
    files: dict[str, Entry]
    iteration: int  # of the checkpoint that vouches for them

    def __contains__(self, path: object) -> bool:
        return isinstance(path, Path) and self._name(path) in self.files

    def _name(self, path: Path) -> str:
        return relative(self.trial_dir, Path(path))

    def read_bytes(self, path: Path, remedy: str) -> bytes:
        """The bytes of a recorded file, after checking them against the record (`verify`);
        `remedy` is what the user can do, said after what is wrong."""
        try:
            data = Path(path).read_bytes()
        except FileNotFoundError:
            raise DamagedFileError(f"{path} is missing: {remedy}") from None
        self.verify(path, data, remedy)
        return data

    def verify(self, path: Path, data: bytes, remedy: str) -> None:
        """DamagedFileError (one line: what is wrong, then `remedy`) unless `data`, read from
        `path`, is what the trial recorded of that file."""
        entry = self.files.get(self._name(path))
        if entry is None:
            raise DamagedFileError(
                f"{path} is not among the files the trial's checkpoint recorded (a stray or "
                f"foreign file?): {remedy}"
            )
        found = entry_of(data)
        if found.size != entry.size:
            raise DamagedFileError(
                f"{path} holds {found.size} bytes where the trial recorded {entry.size} "
                f"(truncated, damaged or replaced): {remedy}"
            )
        if found.sha256 != entry.sha256:
            raise DamagedFileError(
                f"{path} is damaged or replaced (its checksum is not the one the trial "
                f"recorded): {remedy}"
            )

    def problem_with(self, path: Path) -> str | None:
        """What is wrong with a recorded file, in a few words (missing, damaged...), or None
        when it is as recorded."""
        try:
            self.read_bytes(path, "")
        except DamagedFileError as exc:
            return str(exc).split(":")[0]
        return None

    def holds(self, path: Path, data: bytes) -> bool:
        """Whether `data` are the bytes the trial recorded of the file at `path`."""
        return entry_of(data) == self.files.get(self._name(path))

    def check_present(self) -> None:
        """DamagedFileError naming the first recorded file that is missing or of another
        size: a check of every file at the cost of a directory listing."""
        for name, entry in self.files.items():
            path = self.trial_dir / name
            try:
                size = path.stat().st_size
            except FileNotFoundError:
                raise DamagedFileError(f"{path} is missing (recorded by the trial)") from None
            if size != entry.size:
                raise DamagedFileError(
                    f"{path} holds {size} bytes where the trial recorded {entry.size}"
                )


def read_manifest(trial_dir: str | os.PathLike, meta: dict) -> Manifest | None:
    """The manifest of the checkpoint of metadata `meta` in `trial_dir`, every link of its
    chain checked; None for a checkpoint written before manifests. DamagedFileError for a
    manifest file that is missing, damaged or not the one the checkpoint names."""
    trial_dir = Path(trial_dir)
    pointer = meta.get(MANIFEST_KEY)
    if pointer is None:
        return None
    files: dict[str, Entry] = {}
    seen: set[str] = set()
    while pointer is not None:
        name, path = _pointed(trial_dir, pointer, seen)
        seen.add(name)
        try:
            data = path.read_bytes()
        except FileNotFoundError:
            raise DamagedFileError(f"{path} is missing ({_RESUME})") from None
        if entry_of(data).sha256 != pointer["sha256"]:
            raise DamagedFileError(f"{path} is damaged or replaced ({_RESUME})")
        record = storage.json_from_bytes(data, path)
        try:
            period = {k: Entry(int(v[0]), str(v[1])) for k, v in record["files"].items()}
            pointer = record["previous"]
        except (KeyError, TypeError, ValueError, IndexError, AttributeError):
            raise DamagedFileError(f"{path} is not a manifest file ({_RESUME})") from None
        files = {**period, **files}  # older files first; a file is recorded once
    return Manifest(trial_dir, files, int(meta["iteration"]))


def trial_manifest(trial_dir: str | os.PathLike, warn: bool = True) -> Manifest | None:
    """The manifest of a trial's newest checkpoint, for a reader that restores nothing (the logs,
    backend.json); None, with an `UncheckedTrialWarning` if `warn`, for a trial written before
    manifests. DamagedFileError when its checkpoint cannot vouch for anything (unreadable,
    or missing beside a previous one: a resume's to mend)."""
    trial_dir = Path(trial_dir)
    newest = trial_dir / CHECKPOINT_FILE
    if not newest.exists():
        if (trial_dir / PREVIOUS_CHECKPOINT_FILE).exists():
            raise DamagedFileError(
                f"{newest} is missing: `playroom run --out {trial_dir} --resume` continues the "
                f"trial from {PREVIOUS_CHECKPOINT_FILE}"
            )
        if any((trial_dir / MANIFEST_DIR).glob("files-*.json")):
            raise DamagedFileError(
                f"{trial_dir} has lost its checkpoints ({CHECKPOINT_FILE} and "
                f"{PREVIOUS_CHECKPOINT_FILE} are missing): nothing vouches for its files; "
                "restore them from a backup, or run the trial again from scratch into a new "
                "directory"
            )
        if [p for p in data_files(trial_dir) if p.name not in RECORDS.values()]:
            if warn:  # files of a trial from before manifests, whose checkpoints are gone
                warn_unchecked(trial_dir)
            return None
        return Manifest(trial_dir, {}, 0)  # nothing computed yet, nothing vouched for
    try:
        meta = storage.read_meta(newest)
    except storage.CorruptFileError as exc:
        raise DamagedFileError(
            f"{exc}: `playroom run --out {trial_dir} --resume` continues the trial from "
            f"{PREVIOUS_CHECKPOINT_FILE}"
        ) from None
    found = read_manifest(trial_dir, meta)
    if found is None and warn:
        warn_unchecked(trial_dir)
    return found


_RESUME = "a manifest file of the trial's checkpoint; restore it from a backup"


def _pointed(trial_dir: Path, pointer: object, seen: set[str]) -> tuple[str, Path]:
    if not isinstance(pointer, dict) or not isinstance(pointer.get("sha256"), str):
        raise DamagedFileError(f"{trial_dir}'s checkpoint names no usable manifest ({pointer!r})")
    name = pointer.get("name")
    if not isinstance(name, str) or not _MANIFEST.fullmatch(name) or name in seen:
        raise DamagedFileError(f"{trial_dir}'s checkpoint names no usable manifest ({name!r})")
    return name, trial_dir / MANIFEST_DIR / name


def write_period(
    trial_dir: Path,
    iteration: int,
    previous: dict | None,
    written: Iterable[Path],
    identity: dict,
) -> dict:
    """Record the files `written` since the checkpoint whose manifest pointer is `previous`
    (None: the first) in `manifest/files-<iteration>.json`, atomically; returns the pointer the
    checkpoint at `iteration` carries (MANIFEST_KEY). Each file is read back and hashed as it
    lies on disk, which is what every reader will check."""
    files = {relative(trial_dir, p): entry_of(Path(p).read_bytes()).as_json() for p in written}
    record = {"identity": identity, "iteration": iteration, "files": files, "previous": previous}
    data = storage.json_bytes(record)
    folder = trial_dir / MANIFEST_DIR
    folder.mkdir(exist_ok=True)
    name = manifest_name(iteration)
    pointer = {"name": name, "sha256": entry_of(data).sha256}
    storage.write_bytes(folder / name, data)
    return pointer


def recorded_any(trial_dir: str | os.PathLike) -> bool:
    """Whether a trial directory holds any manifest file."""
    return any((Path(trial_dir) / MANIFEST_DIR).glob("files-*.json"))


def drop_past(trial_dir: Path, iteration: int) -> None:
    """Delete the manifest files of checkpoints past `iteration` (written by a run killed
    before its checkpoint, or past the checkpoint a resume falls back to): the run writes them
    again."""
    for path in (Path(trial_dir) / MANIFEST_DIR).glob("files-*.json"):
        match = _MANIFEST.fullmatch(path.name)
        if match is not None and int(match["iteration"]) > iteration:
            path.unlink()


def warn_unchecked(
    trials: str | os.PathLike, category: type[UncheckedTrialWarning] = UncheckedTrialWarning
) -> None:
    """One line: the `trials` (a trial directory, or words naming several) predate manifests
    (or, `category` UncheckedEvaluationWarning, their eval.json predates its checksum), their
    files are read as they are."""
    warnings.warn(f"{trials}: {category.what}", category, stacklevel=3)


def warn_unchecked_once(
    batch_dir: Path, dirs: list[Path], caught: list[warnings.WarningMessage]
) -> None:
    """The warnings reading a batch's trials raised (`caught`), again, those of trials read
    unchecked as one line for the batch per kind (UncheckedTrialWarning and its subclasses)."""
    unchecked: dict[type[UncheckedTrialWarning], list[str]] = {}
    for w in caught:
        if not issubclass(w.category, UncheckedTrialWarning):
            warnings.warn_explicit(w.message, w.category, w.filename, w.lineno)
            continue
        names = unchecked.setdefault(w.category, [])
        text = str(w.message)  # names a trial directory, or a file in it
        named = [d.name for d in dirs if f"{d}:" in text or f"{d}{os.sep}" in text]
        names += [name for name in named if name not in names]
    for category, names in unchecked.items():
        if names:
            trials = f"{len(names)} trial(s) of {batch_dir} ({names[0]}, ...)"
            warn_unchecked(trials, category)


def evaluation_files(files: dict[str, bytes]) -> dict[str, list]:
    """eval.json's EVAL_FILES_KEY entry: each table of an evaluation, name -> [size, sha256]."""
    return {name: entry_of(data).as_json() for name, data in files.items()}


def read_evaluation_file(trial_dir: Path, name: str, summary: dict) -> bytes | None:
    """The bytes of the evaluation table `name` of a trial whose eval.json is `summary`,
    checked against the entry eval.json holds of it; None for a table an evaluation written
    before eval.json listed its tables does not have. DamagedFileError (one line) for a table
    that is missing, or damaged, or of another evaluation."""
    path = Path(trial_dir) / name
    listed = summary.get(EVAL_FILES_KEY)
    remedy = f"evaluate the trial again (`playroom eval {trial_dir}`)"
    if not isinstance(listed, dict):  # before the list: read as it lies
        return path.read_bytes() if path.exists() else None
    try:
        size, sha256 = listed[name]
        recorded = Manifest(Path(trial_dir), {name: Entry(int(size), str(sha256))}, 0)
    except (KeyError, TypeError, ValueError):
        raise DamagedFileError(
            f"{path.parent / 'eval.json'} does not list {name}: {remedy}"
        ) from None
    return recorded.read_bytes(path, remedy)
