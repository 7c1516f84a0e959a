"""A trial's checkpoint read back: used only if it is the trial's own (its identity,
config_file.trial_identity) and readable, with the memory segments it names
(memory_segments.py); the newest is preferred, the previous one is the fallback of a resume
only.

The agent and room a checkpoint is restored into are built by the caller (the run's stage knows
how to build them): here they are only what a checkpoint's state is loaded into (`AgentState`,
`RoomState`), so that reading a trial directory loads no simulator.
"""

from __future__ import annotations

import os
from collections.abc import Callable
from pathlib import Path
from typing import Any, Protocol, TypeVar

import numpy as np

from experiments.trial_dir import manifest, memory_segments, storage
from experiments.trial_dir.config_file import identity_text
from experiments.trial_dir.errors import TrialError
from experiments.trial_dir.layout import (
    CHECKPOINT_FILE,
    LOG_DIR,
    MEMORY_DIR,
    PREVIOUS_CHECKPOINT_FILE,
)


class AgentState(Protocol):
    """What a checkpoint's agent state is loaded into (learner.agent.Agent)."""

    def load_state_dict(self, state: dict[str, Any]) -> None: ...


class RoomState(Protocol):
    """What a checkpoint's room state is loaded into (sim.Playroom)."""

    def set_state(self, state: dict) -> None: ...


A = TypeVar("A", bound=AgentState)
R = TypeVar("R", bound=RoomState)
# How a trial's agent and room at iteration 0 are built, new ones at each call.
Build = Callable[[], tuple[A, R]]


def check_identity(path: Path, meta: dict, own: dict) -> None:
    """TrialError if the checkpoint at `path` belongs to another trial than the one of identity
    `own` (config_file.trial_identity). A checkpoint without identity (written before
    checkpoints carried one) is taken as the trial's: the caller says so where it can."""
    found = meta.get("identity")
    if found is None or found == own:
        return
    raise TrialError(
        f"{path.name} belongs to another trial ({identity_text(found)}) than "
        f"{path.parent} ({identity_text(own)}); refusing to mix them"
    )


def restore_checkpoint(
    trial_dir: str | os.PathLike,
    agent: AgentState,
    room: RoomState,
    name: str = CHECKPOINT_FILE,
    *,
    identity: dict,
) -> tuple[dict, manifest.Manifest | None]:
    """Load a trial's checkpoint, with the memory segments it names, into `agent` and `room`:
    (the checkpoint's metadata with 'best_word_distance' added, its manifest: None before
    manifests), the manifest's chain read once. CorruptFileError if it, its manifest or a
    segment cannot be read or restored; TrialError if either belongs to another trial than the
    one of `identity`."""
    path = Path(trial_dir) / name
    if not path.exists():
        raise storage.CorruptFileError(f"{path} is missing")
    arrays, meta = storage.read_arrays(path)
    check_identity(path, meta, identity)
    recorded = memory_segments.recorded_by(path, meta)
    try:
        arrays = memory_segments.with_rows(path, arrays, meta, recorded)
    except memory_segments.ForeignSegmentError as exc:
        raise TrialError(str(exc)) from None
    try:
        agent.load_state_dict(memory_segments.agent_part(arrays))
        room.set_state({**meta["room"], "physics": arrays["room/physics"]})
        meta["best_word_distance"] = arrays["best_word_distance"].copy()
    except (KeyError, ValueError, TypeError) as exc:
        raise storage.CorruptFileError(f"{path} cannot be restored ({exc})") from None
    return meta, recorded


def restore_newest(
    trial_dir: str | os.PathLike,
    identity: dict,
    first: tuple[A, R] | None,
    build: Build[A, R],
) -> tuple[A, R, dict, manifest.Manifest | None, str | None]:
    """A trial's newest usable checkpoint, restored into fresh parts (`first`, built already,
    then `build`'s): (agent, room, meta, its manifest, fallback), `fallback` None when
    checkpoint.npz was used, else one line saying what is wrong with it (missing, or damaged,
    its manifest included). TrialError if
    neither checkpoint can be used (naming both, and what is wrong with each), or if the one
    read belongs to another trial."""
    trial_dir = Path(trial_dir)
    problems = []
    for name in (CHECKPOINT_FILE, PREVIOUS_CHECKPOINT_FILE):
        # A restore that failed half-way may have changed them: each try starts afresh.
        if first is not None:
            (agent, room), first = first, None
        else:
            agent, room = build()
        try:
            meta, recorded = restore_checkpoint(trial_dir, agent, room, name, identity=identity)
        except storage.CorruptFileError as exc:
            problems.append(" ".join(str(exc).split()))
            continue
        return agent, room, meta, recorded, (problems[0] if problems else None)
    raise TrialError(
        f"{trial_dir} cannot be restored: {problems[0]}; {problems[1]}. Nothing was changed: "
        "a trial without a readable checkpoint can only be run again from scratch, into a new "
        "directory"
    )


def has_checkpoint(trial_dir: str | os.PathLike) -> bool:
    """Whether a trial directory holds a checkpoint, the newest or the previous one."""
    return any((Path(trial_dir) / n).exists() for n in (CHECKPOINT_FILE, PREVIOUS_CHECKPOINT_FILE))


def newest_meta(trial_dir: str | os.PathLike) -> dict:
    """The metadata of a trial's newest checkpoint, its arrays not read: CorruptFileError if
    it cannot be read, FileNotFoundError if it is missing."""
    path = Path(trial_dir) / CHECKPOINT_FILE
    if not path.exists():
        raise FileNotFoundError(path)
    return storage.read_meta(path)


def newest_arrays(trial_dir: str | os.PathLike) -> tuple[dict[str, np.ndarray], dict]:
    """The arrays of a trial's newest checkpoint, every model's memory rows among them (its
    segments read whole), and its metadata. CorruptFileError if it or a segment it names cannot
    be read (memory_segments.ForeignSegmentError for a segment of another trial)."""
    return memory_segments.read_checkpoint(Path(trial_dir) / CHECKPOINT_FILE)


def progress(trial_dir: str | os.PathLike) -> tuple[int, int]:
    """(iteration of the newest readable checkpoint, bytes of checkpoints, memory segments and
    logs) of a trial to be resumed; (0, 0) where there is none yet. A resume checks the trial
    itself."""
    trial_dir = Path(trial_dir)
    iteration = 0
    for name in (CHECKPOINT_FILE, PREVIOUS_CHECKPOINT_FILE):
        try:
            iteration = int(storage.read_meta(trial_dir / name)["iteration"])
            break
        except (storage.CorruptFileError, KeyError, TypeError, ValueError):
            continue
    files = [trial_dir / CHECKPOINT_FILE, trial_dir / PREVIOUS_CHECKPOINT_FILE]
    for folder in (LOG_DIR, MEMORY_DIR):
        files += [p for p in (trial_dir / folder).rglob("*") if p.is_file()]
    return iteration, sum(p.stat().st_size for p in files if p.is_file())
