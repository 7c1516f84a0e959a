"""A trial directory opened for writing, the package's second face (the first is reading.py):
what a writer does to a trial directory, decided and recorded here, so that it names no file.

- `open_for_writing(...)`: a trial's run, started or resumed: the opening's decision
  (opening.py: the directory checked, locked, config.json written or compared, a resume's
  checkpoint restored, an extension), what the run declares of itself recorded
  (provenance.json, backend.json), then its recorded writes (`TrialWriter`): each checkpoint
  period's log chunks and memory segment, the manifest of what was written since the
  checkpoint before, and the checkpoint.
- `open_for_evaluation(trial_dir)`: the trial's derived files, under its lock
  (`EvaluationWriter`): the trial restored and checked whole, a killed writer's litter removed,
  its evaluation in a world written as one unit, eval.json last; and the batch task's timing
  (`write_timing`).

Order on disk, for crash safety: a period's chunks and memory segment, then its manifest file,
then the checkpoint that names it (manifest.py, memory_segments.py). No simulator is loaded:
the agent and room are the caller's, of which only what is written is asked for.
"""

from __future__ import annotations

import os
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Generic, Protocol

import numpy as np
import pandas as pd

from experiments.trial_dir import backend_record, manifest, memory_segments, records, storage
from experiments.trial_dir.checkpoint import A, Build, R
from experiments.trial_dir.errors import TrialError, TrialLocked
from experiments.trial_dir.evaluation import Evaluation, evaluation_files
from experiments.trial_dir.layout import (
    BACKEND_FILE,
    CHECKPOINT_FILE,
    CHUNK_IDENTITY_KEY,
    MEMORY_DIR,
    PREVIOUS_CHECKPOINT_FILE,
    TIMING_FILE,
    chunk_file,
)
from experiments.trial_dir.lock import DirectoryLock, DirectoryLocked
from experiments.trial_dir.log_schema import SOURCE_COLUMNS
from experiments.trial_dir.opening import OpenedTrial as OpenedTrial
from experiments.trial_dir.opening import open_trial_directory
from experiments.trial_dir.provenance_file import record_start
from experiments.trial_dir.reading import TrialReading
from experiments.trial_dir.storage import remove_litter


class Checkpointed(memory_segments.Memories, Protocol):
    """What a checkpoint holds of an agent (learner.agent.Agent): its state, each model's rows
    past those its memory segments hold."""

    def state_dict(self, rows_from: dict[int, int] | None = None) -> dict[str, np.ndarray]: ...


class RoomState(Protocol):
    """What a checkpoint holds of a room (sim.Playroom): its state, its physics' as arrays."""

    def get_state(self) -> dict: ...


@dataclass(frozen=True)
class Declared:
    """What a run declares of itself before it computes: the inputs it computes with, beside the
    machine and code (provenance.json: provenance_file.record_start), and what its grasp
    backend declares (backend.json: records.regenerate)."""

    inputs: dict[str, str] | None
    grasp: str
    reach: float
    capabilities: dict[str, bool]


class TrialWriter(Generic[A, R]):
    """A trial directory opened for its run (`open_for_writing`), locked until `close`: what the
    run starts from (`opened`), and the writes it records."""

    def __init__(self, opened: OpenedTrial[A, R]) -> None:
        self.opened = opened
        self.dir = opened.dir
        # Where the checkpoint period being computed starts: its chunks are named by it.
        self._period_start = opened.iteration
        # What the memory's segments hold (each checkpoint holds the rest), the newest manifest
        # file, the manifest of the checkpoint restored, the data files written since it.
        self._memory = opened.memory
        self._pointer = opened.manifest_pointer
        self._recorded = opened.recorded
        self._unrecorded = opened.unrecorded

    def close(self) -> None:
        """Give up the directory's lock."""
        self.opened.lock.release()

    def has_checkpoint(self) -> bool:
        return (self.dir / CHECKPOINT_FILE).exists()

    def _record_declared(self, declared: Declared, finished: bool) -> None:
        """What the run declares, recorded before it computes, the lines to tell the user
        added to the opening's notices: who computes from here on (provenance.json), unless
        the trial is `finished`; what its backend declares, for analysis to read
        (backend.json); and a finished trial's summary. Each record is written once, or
        rewritten when lost or damaged if what computes it now gives what the trial recorded
        (records.regenerate). A finished trial from before backend.json is left without one:
        readers compute it from its config."""
        notices = self.opened.notices
        if not finished:
            notices += record_start(self.dir, self.opened.iteration, declared.inputs)
        backend = None
        if not finished or (self.dir / BACKEND_FILE).exists() or self._recorded is not None:
            backend = backend_record.make_record(
                declared.grasp, declared.reach, declared.capabilities
            )
        wanted: dict[str, tuple[dict, str]] = {}  # in this order: the summary first
        summary_path = records.record_path(self.dir, "summary")
        if finished and self._recorded is not None and summary_path in self._recorded:
            opened = self.opened
            summary = records.summary_record(
                opened.iteration, opened.counts, opened.best_word_distance
            )
            wanted["summary"] = summary, "the trial's last checkpoint"
        if backend is not None:
            wanted["backend"] = backend, "the backend's declaration"
        for kind, (record, computed_from) in wanted.items():
            notice = records.regenerate(
                self.dir, kind, record, self._recorded, self._unrecorded, computed_from
            )
            if notice is not None:
                notices.append(notice)

    def _write_chunk(self, kind: str, table: pd.DataFrame, plain: tuple[str, ...]) -> None:
        """One chunk of a log, of the period being closed, in its kind's folder, its source
        columns first, carrying the trial's identity; recorded by the period's manifest."""
        for position, column in enumerate(SOURCE_COLUMNS):
            table.insert(position, column, self.opened.source[column])
        path = self.dir / chunk_file(kind, self._period_start)
        path.parent.mkdir(exist_ok=True)
        # Written into the Parquet schema's metadata (layout.py).
        table.attrs[CHUNK_IDENTITY_KEY] = self.opened.identity
        storage.write_table(path, table, plain=plain)
        self._unrecorded.append(path)

    def save_checkpoint(
        self,
        agent: Checkpointed,
        room: RoomState,
        iteration: int,
        finished: bool,
        counts: dict[str, int],
        best_word_distance: np.ndarray,
        logs: Mapping[str, tuple[pd.DataFrame, tuple[str, ...]]] | None = None,
    ) -> None:
        """The checkpoint at `iteration`, closing the period since the last one, in the order
        that survives a kill: the period's `logs` (kind -> (its rows, the columns written
        plain)) as chunks, the rows the memory stored since the last checkpoint in a segment of
        their own, then the manifest of every file written since it, then the checkpoint (the
        agent's state past its segments, the room's, where the run stands), the one before it
        kept as the previous."""
        for kind, (table, plain) in (logs or {}).items():
            self._write_chunk(kind, table, plain)
        if finished:  # where the run ended, for a reader without NumPy
            summary = records.summary_record(iteration, counts, best_word_distance)
            records.write_new(self.dir, "summary", summary, self._unrecorded)
        memory = memory_segments.write_segment(
            self.dir, agent, self._memory, iteration, self.opened.identity
        )
        memory_meta = memory.meta()
        if memory.newest != self._memory.newest:
            self._unrecorded.append(self.dir / MEMORY_DIR / str(memory.newest))
        pointer = manifest.write_period(
            self.dir, iteration, self._pointer, self._unrecorded, self.opened.identity
        )
        room_state = room.get_state()
        # The agent's state is plain arrays (its config and generator as 0-d JSON strings).
        state = agent.state_dict(rows_from=memory.rows)
        arrays = {f"{memory_segments.AGENT}{k}": v for k, v in state.items()}
        arrays["room/physics"] = room_state.pop("physics")
        arrays["best_word_distance"] = best_word_distance
        meta = {
            "iteration": iteration,
            "finished": finished,
            "room": room_state,
            "counts": counts,
            # Whose checkpoint it is: one copied into another trial is refused there.
            "identity": self.opened.identity,
            # The name the trial was created as, which its log rows carry wherever it lies.
            "trial_name": self.opened.source["trial"],
            memory_segments.MEMORY_KEY: memory_meta,
            manifest.MANIFEST_KEY: pointer,
        }
        newest = self.dir / CHECKPOINT_FILE
        if newest.exists():
            # Kept as the previous one by a second name, not moved: at every moment the trial
            # has a whole checkpoint.npz (moved, there was none while the new one was written,
            # and a writer killed then left only the previous one).
            storage.keep_copy(newest, self.dir / PREVIOUS_CHECKPOINT_FILE)
        storage.write_arrays(newest, arrays, meta)
        self._memory = memory
        self._pointer, self._unrecorded = pointer, []
        self._period_start = iteration


def open_for_writing(
    out_dir: str | os.PathLike,
    config: dict,
    parts: tuple[A, R],
    build: Build[A, R],
    resume: bool,
    words: int,
    fits: Callable[[Path], str | None],
    declared: Declared,
) -> TrialWriter[A, R]:
    """A trial directory opened for the run of the trial of `config`
    (opening.open_trial_directory decides, and says what each argument but the last is), what
    the run `declared` recorded, locked until the writer is closed. TrialError (one line) if it
    cannot be used."""
    opened = open_trial_directory(out_dir, config, parts, build, resume, words, fits)
    writer = TrialWriter(opened)
    try:
        writer._record_declared(declared, opened.iteration >= config["trial"]["iterations"])
    except BaseException:
        writer.close()
        raise
    return writer


@dataclass
class EvaluationWriter:
    """A trial directory opened for its derived files (`open_for_evaluation`), locked until
    `close`; `trial` reads it."""

    trial: TrialReading
    lock: DirectoryLock

    def close(self) -> None:
        self.lock.release()

    def remove_litter(self) -> list[str]:
        """The temporary files of killed writers removed (under the lock: their writers are
        dead); their paths in the directory."""
        return remove_litter(self.trial.dir)

    def check_writable(self, evaluation: Evaluation) -> None:
        """TrialError, before minutes of tests whose results could not be kept, unless the
        folder of `evaluation` can be written."""
        try:
            storage.check_writable(evaluation.folder)
        except OSError as exc:
            raise TrialError(
                f"cannot write into {evaluation.folder}: {storage.reason(exc)}"
            ) from None

    def write(
        self, evaluation: Evaluation, summary: dict, tables: dict[str, bytes], config: dict
    ) -> None:
        """`evaluation`'s files written as one unit, eval.json last (evaluation_files:
        `tables` by kind, `summary` its numbers, `config` the trial's config.json): a write that
        fails (disk full) leaves the evaluation's files as they were."""
        storage.write_files(evaluation.folder, evaluation_files(summary, tables, config))


def open_for_evaluation(trial_dir: str | os.PathLike) -> EvaluationWriter:
    """A trial directory opened for its derived files, its lock taken before the trial is read:
    a live writer's files are caught mid-change (its checkpoint between two renames), and it is
    the writer that must be named (TrialLocked). TrialError for a folder that holds no trial,
    or whose lock cannot be made or opened for writing (read-only)."""
    trial = TrialReading(Path(trial_dir))
    if not trial.config_path.is_file():  # the lock would make the folder
        raise TrialError(trial.no_trial_line())
    try:
        lock = DirectoryLock(trial.dir).acquire()
    except DirectoryLocked as exc:
        raise TrialLocked(str(exc)) from None
    except OSError as exc:  # the lock file cannot be made or opened for writing: read-only
        raise TrialError(f"cannot write into {trial.dir}: {storage.reason(exc)}") from None
    return EvaluationWriter(trial, lock)


def write_timing(trial_dir: str | os.PathLike, seconds: float, iterations: int) -> None:
    """timing.json, derived from the trial's last run: its `seconds` and the `iterations` they
    ran (a resumed trial's, those of this run only: a fair cost). Written by the batch task
    that ran the trial, under its lock."""
    storage.write_json(
        Path(trial_dir) / TIMING_FILE, {"seconds": seconds, "iterations": iterations}
    )
