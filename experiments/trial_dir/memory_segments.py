"""The models' memories on disk, each row written once: checkpoints whose cost is what changed.

A model's memory only grows, by about a row an iteration (learner/sensorimotor_model.py). A
checkpoint holding every row rewrote them all each time: its bytes grew with the trial's
length, and the bytes written over a trial with the square of it (416 MB
checkpoints by iteration 681000, one every 1000 iterations). So the rows live apart, in
append-only segments, and a checkpoint writes only those stored since the one before it:

- `memory/rows-NNNNNNNN.npz` (experiments/trial_dir/layout.py names it): the rows every model
  stored over the checkpoint period that starts at iteration NNNNNNNN, under the keys of
  Agent.state_dict (`model{number}.motor`, `model{number}.key`); in its metadata, the trial's
  identity (as log chunks and checkpoints carry it), the period's first and last iteration,
  the row each model's rows start at (`first_rows`), and the segment before it (`previous`,
  None for the first). A period that stored no row has none.
- The checkpoint holds the rest of the agent's state, with each model's rows past its
  segments (none), and in its metadata (MEMORY_KEY) the rows its segments hold per model and
  the newest of them: `previous` leads from it to the first, so that its size does not grow
  with the trial.

Crash safety, a run killed (SIGKILL) at any moment resuming bit for bit. A segment is written
atomically (storage.write_arrays), after the period's log chunks and before the checkpoint
that names it, and never changes once a usable checkpoint names it (a run writes only the
segment of the period after the checkpoint it resumed from):
- killed while writing it: its temporary file is litter (checks.remove_litter);
- killed after it, before the checkpoint: the newest checkpoint is the period's start, and the
  segment of that period lies beyond it. A resume deletes such segments with the logs past the
  checkpoint (`drop_segments_past`), and the run writes the same one again; a reader that does
  not resume (an evaluation) never reaches it, as nothing names it;
- a checkpoint damaged or lost: the previous one names only older segments, which no run
  writes again, and the resume redoes the periods after it as above;
- a segment missing, damaged or not continuing the one before it: the checkpoint that names
  it is unusable (CorruptFileError naming both), and a resume falls back to the previous one
  as for a damaged checkpoint; one of another trial is refused (ForeignSegmentError).

Old checkpoints, written before segments, hold every row in their own arrays and no MEMORY_KEY:
they are read as they are, and the first checkpoint after them writes every row once, as the
first segment. Restoring joins a model's rows from its segments, oldest first, then the
checkpoint's own: the same arrays, bit for bit, as one checkpoint held (`with_rows`).
"""

from __future__ import annotations

import dataclasses
import re
from pathlib import Path
from typing import Protocol

import numpy as np

from experiments.trial_dir import manifest, storage
from experiments.trial_dir.config_file import identity_text
from experiments.trial_dir.layout import MEMORY_DIR, MEMORY_SEGMENT_PREFIX, memory_segment_name

# A checkpoint's keys for the agent's state: AGENT + a key of Agent.state_dict.
AGENT = "agent/"


def agent_part(arrays: dict[str, np.ndarray]) -> dict[str, np.ndarray]:
    """The agent's state among a checkpoint's `arrays`, by the keys of Agent.state_dict."""
    return {k.removeprefix(AGENT): v for k, v in arrays.items() if k.startswith(AGENT)}


# The checkpoint metadata's entry on its memory (what `MemoryOnDisk.meta` writes).
MEMORY_KEY = "memory"
_PARTS = ("motor", "key")  # each model's arrays of rows, as Agent.state_dict names them
_SEGMENT = re.compile(re.escape(MEMORY_SEGMENT_PREFIX) + r"(?P<start>[0-9]{8,})\.npz")


class Memories(Protocol):
    """What stores a trial's memories (learner.agent.Agent): each model's rows, and those of
    them stored from a row on."""

    def memory_sizes(self) -> dict[int, int]: ...

    def memory_rows(self, rows_from: dict[int, int]) -> dict[str, np.ndarray]: ...


class ForeignSegmentError(storage.CorruptFileError):
    """A segment that carries another trial's identity than the checkpoint naming it."""


@dataclasses.dataclass(frozen=True)
class MemoryOnDisk:
    """What a trial's segments hold as of its checkpoint at `iteration`: the rows of each model
    (by number; a model not named, none) and the newest segment's name (None: no segment)."""

    rows: dict[int, int]
    newest: str | None
    iteration: int

    def meta(self) -> dict:
        """The checkpoint metadata's MEMORY_KEY entry."""
        return {"segment_rows": {str(n): c for n, c in self.rows.items()}, "newest": self.newest}


def on_disk(meta: dict) -> MemoryOnDisk:
    """What the segments hold as of the checkpoint of metadata `meta` (read and restored by
    `with_rows` already): for an old checkpoint, nothing, so that the next writes every row."""
    memory = meta.get(MEMORY_KEY)
    if memory is None:
        return MemoryOnDisk({}, None, int(meta["iteration"]))
    rows = {int(n): int(c) for n, c in memory["segment_rows"].items()}
    return MemoryOnDisk(rows, memory["newest"], int(meta["iteration"]))


def write_segment(
    trial_dir: Path, agent: Memories, held: MemoryOnDisk, iteration: int, identity: dict
) -> MemoryOnDisk:
    """Write the rows `agent` stored since `held` (its trial's checkpoint before this one, at
    `held.iteration`) as one segment, atomically; returns what the segments then hold, for the
    checkpoint at `iteration` to record. A period that stored no row writes nothing."""
    sizes = agent.memory_sizes()
    rows_from = {n: held.rows.get(n, 0) for n in sizes}
    if sizes == rows_from:
        return dataclasses.replace(held, rows=sizes, iteration=iteration)
    shrunk = [n for n in sizes if sizes[n] < rows_from[n]]
    if shrunk:  # rows are only appended: a writer's mistake, never the trial's
        raise ValueError(f"models {shrunk} hold fewer rows than the segments already written")
    name = memory_segment_name(held.iteration)
    meta = {
        "identity": identity,
        "iterations": [held.iteration, iteration],
        "first_rows": {str(n): r for n, r in rows_from.items()},
        "previous": held.newest,
    }
    folder = Path(trial_dir) / MEMORY_DIR
    folder.mkdir(exist_ok=True)
    storage.write_arrays(folder / name, agent.memory_rows(rows_from), meta)
    return MemoryOnDisk(sizes, name, iteration)


def read_checkpoint(path: Path) -> tuple[dict[str, np.ndarray], dict]:
    """A checkpoint's arrays, every model's rows among them (`with_rows`), and metadata.
    CorruptFileError if it, its manifest or a segment it names cannot be read
    (ForeignSegmentError for a segment of another trial)."""
    arrays, meta = storage.read_arrays(path)
    return with_rows(path, arrays, meta, recorded_by(path, meta)), meta


def recorded_by(checkpoint: Path, meta: dict) -> manifest.Manifest | None:
    """The manifest of the checkpoint at `checkpoint` (metadata `meta`), its chain read once for
    the segments and then for whatever the checkpoint covers; None before manifests.
    CorruptFileError (manifest.DamagedFileError) if it cannot vouch for anything."""
    try:
        return manifest.read_manifest(checkpoint.parent, meta)
    except (KeyError, TypeError, ValueError, AttributeError) as exc:  # written by no writer
        raise storage.CorruptFileError(f"{checkpoint} cannot be restored ({exc})") from None


def with_rows(
    checkpoint: Path,
    arrays: dict[str, np.ndarray],
    meta: dict,
    recorded: manifest.Manifest | None,
) -> dict:
    """The arrays of the checkpoint at `checkpoint` (`arrays`, `meta`: as read; `recorded`, its
    manifest: `recorded_by`) with each model's rows whole: those of the segments its metadata
    names, oldest first, then its own (an old checkpoint's own are all of them), each segment's
    bytes as the manifest recorded them. CorruptFileError naming what is missing, damaged or
    inconsistent; ForeignSegmentError for a segment of another trial."""
    if MEMORY_KEY not in meta:
        return arrays
    try:
        return _joined(checkpoint, arrays, meta, recorded)
    except (KeyError, TypeError, ValueError, AttributeError) as exc:  # written by no writer
        raise storage.CorruptFileError(f"{checkpoint} cannot be restored ({exc})") from None


def _joined(
    checkpoint: Path, arrays: dict[str, np.ndarray], meta: dict, recorded: manifest.Manifest | None
) -> dict:
    """`with_rows` of a checkpoint with segments."""
    held = on_disk(meta)
    parts: dict[str, list[np.ndarray]] = {f"model{n}.{p}": [] for n in held.rows for p in _PARTS}
    found = dict.fromkeys(held.rows, 0)
    for path, rows, first in _segments(checkpoint, held.newest, meta.get("identity"), recorded):
        for n in held.rows:
            motor, key = (rows.get(f"model{n}.{p}", np.zeros((0, 0))) for p in _PARTS)
            if first.get(str(n)) != found[n] or motor.ndim != 2 or len(motor) != len(key):
                raise storage.CorruptFileError(
                    f"{path} does not continue the segments before it (model {n}: rows from "
                    f"{first.get(str(n))}, {motor.shape} commands, {key.shape} keys, after "
                    f"{found[n]} rows) ({_of(checkpoint)})"
                )
            found[n] += len(motor)
            parts[f"model{n}.motor"].append(motor)
            parts[f"model{n}.key"].append(key)
    if found != held.rows:
        raise storage.CorruptFileError(
            f"{checkpoint} says its memory segments hold {held.rows} rows, they hold {found}"
        )
    whole = dict(arrays)
    for name, earlier in parts.items():
        own = arrays[AGENT + name]  # the rows past the segments: none
        whole[AGENT + name] = np.concatenate([*earlier, own]) if earlier else own
    return whole


def _segments(
    checkpoint: Path, newest: str | None, identity: object, recorded: manifest.Manifest | None
) -> list[tuple[Path, dict[str, np.ndarray], dict]]:
    """(path, arrays, first_rows) of each segment that `previous` leads to from `newest`,
    oldest first, each read whole, as the checkpoint's manifest (`recorded`, if any) recorded
    it, and of the trial of `identity` (the checkpoint's)."""
    found = []
    name, seen = newest, set()
    while name is not None:
        if not isinstance(name, str) or not _SEGMENT.fullmatch(name) or name in seen:
            raise storage.CorruptFileError(f"{checkpoint} names no usable segment ({name!r})")
        seen.add(name)
        path = checkpoint.parent / MEMORY_DIR / name
        if not path.exists():
            raise storage.CorruptFileError(f"{path} is missing ({_of(checkpoint)})")
        data = path.read_bytes()
        try:
            arrays, meta = storage.read_arrays(path, data)
        except storage.CorruptFileError as exc:
            raise storage.CorruptFileError(f"{exc} ({_of(checkpoint)})") from None
        if identity is not None and meta.get("identity") != identity:
            raise ForeignSegmentError(
                f"{path} belongs to another trial ({identity_text(meta.get('identity'))}) than "
                f"{checkpoint} ({identity_text(identity)}); refusing to mix them"
            )
        if recorded is not None:  # checked after the identity, which names a foreign one
            recorded.verify(path, data, _of(checkpoint))
        first = meta.get("first_rows")
        if not isinstance(first, dict):
            raise storage.CorruptFileError(f"{path} names no first rows ({_of(checkpoint)})")
        found.append((path, arrays, first))
        name = meta.get("previous")
    return found[::-1]


def _of(checkpoint: Path) -> str:
    return f"a memory segment of {checkpoint.name}"


def drop_segments_past(trial_dir: Path, iteration: int) -> None:
    """Delete the segments of periods starting at `iteration` or later: written by a run
    killed before the checkpoint that would have named them, past the checkpoint a resume
    starts from (none it names: its segments' periods start before it); the run writes them
    again."""
    for path in (Path(trial_dir) / MEMORY_DIR).glob(f"{MEMORY_SEGMENT_PREFIX}*.npz"):
        match = _SEGMENT.fullmatch(path.name)
        if match is not None and int(match["start"]) >= iteration:
            path.unlink()
