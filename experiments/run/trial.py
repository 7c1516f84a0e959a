"""One trial: the Model Babbling agent playing in one room, written to a directory that
survives being killed (its files: experiments/run/trial_files.py).

Each file is written atomically, and a log chunk, like the segment of the memory's new rows
(experiments/run/memory_segments.py), is always written before the checkpoint that covers it,
so a run killed at any moment resumes from its last checkpoint and rewrites the same chunks and
segments: the final memory and logs equal those of an uninterrupted run.

One process writes into a trial directory at a time (experiments/run/lock.py). Resuming with more
iterations than the trial was asked for extends it: the result equals a run asked for the
larger number from the start, and files derived from the shorter run (its evaluation) are
moved aside into `stale-at-NNNNNNNN/`.
"""

from __future__ import annotations

import os
import time
from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
import pandas as pd
from tqdm import tqdm

from experiments import backend_record, manifest, provenance, storage
from experiments.file_names import (
    BACKEND_FILE,
    CHECKPOINT_FILE,
    LOG_DIR,
    LOG_README_FILE,
    MEMORY_DIR,
    PREVIOUS_CHECKPOINT_FILE,
)
from experiments.log_layout import CHUNK_IDENTITY_KEY, chunk_path, source_of
from experiments.log_schema import LEARNER_COLUMNS, LEARNER_DTYPE, SOURCE_COLUMNS
from experiments.run import estimate, memory_segments, progress_bar, stop_requests
from experiments.run.lock import DirectoryLock, DirectoryLocked
from experiments.run.settings import TrialSettings, typed_config
from experiments.run.trial_files import (
    LOG_README,
    WORDS_LOG_PERIOD,
    TrialError,
    TrialLocked,
    created_as,
    learner_values,
    log_row,
    trial_identity,
    trial_parts,
    trial_path,
)
from experiments.run.trial_opening import open_trial_directory, refuse_foreign_path
from models.layout import TOYS, block_slice

if TYPE_CHECKING:
    from learner.agent import Agent
    from sim.playroom import Playroom

_SOUND = block_slice("sound")
_TOY_MOVED_BY = tuple(f"{toy}_moved_by" for toy in TOYS)


class Trial:
    """A trial directory and the loop that fills it. It holds the directory's lock from its
    creation until `close` (or the end of the process)."""

    def __init__(self, out_dir: str | os.PathLike, settings: TrialSettings, resume: bool = False):
        self.dir = trial_path(out_dir)
        self.settings = settings
        typed = typed_config(settings)  # the settings typed once, here
        self.config = typed.json
        self.identity = trial_identity(self.config)  # carried by every checkpoint and log chunk
        self.source = source_of(self.dir, self.config)  # first in every log row
        self.notices: list[str] = []  # one line each: what a resume had to do
        refuse_foreign_path(self.dir)
        try:
            self._lock = DirectoryLock(self.dir).acquire()
        except DirectoryLocked as exc:
            raise TrialLocked(str(exc)) from None
        except OSError as exc:
            raise TrialError(f"cannot write into {self.dir}: {exc.strerror}") from None
        try:
            # Built before anything is written: a config that makes no room or agent leaves
            # the directory as it was.
            self.agent, self.room = trial_parts(
                settings.grasp, settings.seed, typed.world, typed.voice, typed.learner
            )
            restored = open_trial_directory(self.dir, self.config, resume, self.notices)
            self.iteration = 0
            self.best_word_distance = np.full(len(self.room.vocal_tract.config.words), np.inf)
            self.counts = {"tool_uses": 0, "words_recognised": 0, "diverged": 0, "stick_returns": 0}
            self.elapsed: float | None = None  # seconds of the last `run_trial`
            self.start_iteration = 0
            # What the memory's segments hold (none yet): each checkpoint writes the rest.
            self.memory = memory_segments.MemoryOnDisk({}, None, 0)
            # The newest manifest file (experiments/manifest.py), and the data files written
            # since it, which the next checkpoint records.
            self.manifest_pointer: dict | None = None
            self.recorded: manifest.Manifest | None = None
            self.unrecorded: list[Path] = []
            if restored is not None:
                self._continue_from(*restored)
            readme = self.dir / LOG_DIR / LOG_README_FILE
            if not readme.exists():  # a new trial's, or an old one's moved into the folders
                storage.write_text(readme, LOG_README)
            if not self.finished:  # who computes from here on (provenance.json)
                self.notices += provenance.record_start(
                    self.dir, self.iteration, self.room.vocal_tract.data_record()
                )
            self._record_backend()
        except BaseException:
            self.close()
            raise

    def close(self) -> None:
        """Give up the directory's lock."""
        self._lock.release()

    def _record_backend(self) -> None:
        """What the trial's backend declares, for analysis to read (backend.json): written once,
        or rewritten when lost or damaged if the backend declares what the trial recorded."""
        backend = self.room.backend
        record = backend_record.make_record(backend.name, backend.reach(), backend.capabilities())
        if self.finished and not (self.dir / BACKEND_FILE).exists() and self.recorded is None:
            return  # a finished trial from before backend.json: read from its config instead
        notice = backend_record.write_once(self.dir, record, self.recorded)
        if notice is not None:
            self.notices.append(notice)
        path = self.dir / BACKEND_FILE
        if self.recorded is None or path not in self.recorded:
            self.unrecorded.append(path)

    @property
    def finished(self) -> bool:
        return self.iteration >= self.settings.iterations

    # Checkpoints --------------------------------------------------------------------------
    def _save_checkpoint(self) -> None:
        # The rows the memory stored since the last checkpoint, in a segment of their own, on
        # disk before the checkpoint that names it; the checkpoint holds the rest.
        memory = memory_segments.write_segment(
            self.dir, self.agent, self.memory, self.iteration, self.identity
        )
        if memory.newest != self.memory.newest:
            self.unrecorded.append(self.dir / MEMORY_DIR / str(memory.newest))
        # Every file written since the last checkpoint, recorded before the checkpoint that
        # names the record (experiments/manifest.py).
        pointer = manifest.write_period(
            self.dir, self.iteration, self.manifest_pointer, self.unrecorded, self.identity
        )
        room_state = self.room.get_state()
        # The agent's state is plain arrays (its config and generator as 0-d JSON strings).
        state = self.agent.state_dict(rows_from=memory.rows)
        arrays = {f"{memory_segments.AGENT}{k}": v for k, v in state.items()}
        arrays["room/physics"] = room_state.pop("physics")
        arrays["best_word_distance"] = self.best_word_distance
        meta = {
            "iteration": self.iteration,
            "finished": self.finished,
            "room": room_state,
            "counts": self.counts,
            # Whose checkpoint it is: one copied into another trial is refused there.
            "identity": self.identity,
            # The name the trial was created as, which its log rows carry wherever it lies.
            "trial_name": self.source["trial"],
            memory_segments.MEMORY_KEY: memory.meta(),
            manifest.MANIFEST_KEY: pointer,
        }
        newest = self.dir / CHECKPOINT_FILE
        if newest.exists():
            # Killed between these two lines, the trial still has the previous checkpoint.
            os.replace(newest, self.dir / PREVIOUS_CHECKPOINT_FILE)
        storage.write_arrays(newest, arrays, meta)
        self.memory = memory
        self.manifest_pointer, self.unrecorded = pointer, []

    def _continue_from(
        self, agent: Agent, room: Playroom, meta: dict, recorded: manifest.Manifest | None
    ) -> None:
        """The trial as the checkpoint a resume restored left it (`open_trial_directory`)."""
        self.agent, self.room, self.recorded = agent, room, recorded
        self.iteration = int(meta["iteration"])
        self.best_word_distance = np.asarray(meta["best_word_distance"], dtype=float)
        self.counts = dict(meta["counts"])
        self.memory = memory_segments.on_disk(meta)
        self.source["trial"] = created_as(self.dir, meta, str(self.source["trial"]))
        self.manifest_pointer = meta.get(manifest.MANIFEST_KEY)
        if self.manifest_pointer is None:
            # A trial written before manifests: its next checkpoint records every data file
            # it holds, as checked by the resume, and it is checked from then on.
            self.unrecorded = manifest.data_files(self.dir)

    # The loop -----------------------------------------------------------------------------
    def run(
        self, progress: bool = True, report: Callable[[int], None] | None = None, every: int = 100
    ) -> None:
        """Run until `iterations`, checkpointing every `checkpoint_every` iterations; `report`
        is told the iteration reached every `every` iterations and at the end (a batch's
        progress, experiments/batches/progress.py)."""
        total = self.settings.iterations
        if report is not None:  # running from here: where a resumed trial starts
            report(self.iteration)
        # `with`: the bar's line is ended however the run ends (Ctrl-C, disk full), before
        # the command's last line.
        desc = f"{self.settings.grasp} seed {self.settings.seed}"
        with progress_bar.trial_bar(total, self.iteration, progress, desc) as bar:
            self._run_to(total, bar, report, every)
            bar.set_postfix(self.counts)
        if report is not None and self.iteration % every != 0:  # the end, if not yet told
            report(self.iteration)

    def _run_to(
        self, total: int, bar: tqdm, report: Callable[[int], None] | None, every: int
    ) -> None:
        """Iterate until `total`, writing logs and a checkpoint every `checkpoint_every`."""
        if self.iteration == 0 and not (self.dir / CHECKPOINT_FILE).exists():
            # A checkpoint before the first log chunk: a directory with logs then always has
            # a checkpoint, unless it was lost, and a resume can tell which
            # (experiments/run/trial_checks.py, `prepare_resume`).
            self._save_checkpoint()
        rows: list[tuple[dict, np.ndarray]] = []
        word_rows: list[dict] = []
        chunk_start = self.iteration
        while self.iteration < total:
            stop_requests.raise_if_requested()  # one dropped in a finalizer (see there)
            started = progress_bar.clock()
            rows.append(self._iterate())
            progress_bar.leave_out_stall(bar, progress_bar.clock() - started)
            self.iteration += 1
            if self.iteration % WORDS_LOG_PERIOD == 0:
                word_rows.append(self._word_row())
            bar.update(1)
            if self.iteration % 50 == 0:
                bar.set_postfix(self.counts, refresh=False)
            if report is not None and self.iteration % every == 0:
                report(self.iteration)
            if self.iteration % self.settings.checkpoint_every == 0 or self.iteration == total:
                self._write_logs(chunk_start, rows, word_rows)
                self._save_checkpoint()
                rows, word_rows, chunk_start = [], [], self.iteration

    def _iterate(self) -> tuple[dict, np.ndarray]:
        """One iteration: its row of events (`log_row`) and its learner's values."""
        interests = self.agent.interests()  # what this iteration's model was chosen from
        proposal, context, feedback = self.agent.play(self.room)
        if proposal.motor_space == "voice":
            sound = feedback.s[_SOUND]
            distances = self.room.vocal_tract.word_distances(sound)
            np.minimum(self.best_word_distance, distances, out=self.best_word_distance)
        row = log_row(self.iteration, proposal, feedback, context)
        self.counts["tool_uses"] += sum(row[column] == "stick" for column in _TOY_MOVED_BY)
        self.counts["words_recognised"] += row["word_recognised"] != ""
        self.counts["diverged"] += row["diverged"]
        self.counts["stick_returns"] += row["stick_returned"]
        return row, learner_values(proposal, self.agent.outcome(proposal, feedback.s), interests)

    def _word_row(self) -> dict:
        row: dict[str, float] = {"iteration": self.iteration}
        words = self.room.vocal_tract.config.words
        for word, best in zip(words, self.best_word_distance, strict=True):
            row[word] = float(best)
        return row

    def _write_logs(
        self, start: int, rows: list[tuple[dict, np.ndarray]], word_rows: list[dict]
    ) -> None:
        events = pd.DataFrame([row for row, _ in rows])
        values = np.vstack([v for _, v in rows]).astype(LEARNER_DTYPE)
        learner = pd.DataFrame(values, columns=list(LEARNER_COLUMNS))
        iterations = pd.concat([events, learner], axis=1)
        self._write_chunk("iterations", start, iterations, plain=LEARNER_COLUMNS)
        if word_rows:
            self._write_chunk("words", start, pd.DataFrame(word_rows))

    def _write_chunk(
        self, kind: str, start: int, table: pd.DataFrame, plain: tuple[str, ...] = ()
    ) -> None:
        """One chunk of a log, in its kind's folder, its source columns first, carrying the
        trial's identity."""
        for position, column in enumerate(SOURCE_COLUMNS):
            table.insert(position, column, self.source[column])
        path = chunk_path(self.dir, kind, start)
        path.parent.mkdir(exist_ok=True)
        # Written into the Parquet schema's metadata (experiments/log_layout.py).
        table.attrs[CHUNK_IDENTITY_KEY] = self.identity
        storage.write_table(path, table, plain=plain)
        self.unrecorded.append(path)


def run_trial(
    out_dir: str | os.PathLike,
    settings: TrialSettings,
    resume: bool = False,
    progress: bool = True,
    notify: Callable[[str], None] | None = None,
    report: Callable[[int], None] | None = None,
    report_every: int = 100,
) -> Trial:
    """Create (or resume) a trial in out_dir and run it to the end. `notify` is called, before
    the run, with each line a resume has to report (a fallback checkpoint, an extension);
    `report` with the iteration reached, every `report_every` iterations and at the end.
    A trial that will not fit on its disk is refused first (TrialError); a long one is told
    to `notify`, first, with its expected time and disk (experiments/run/estimate.py)."""
    line = estimate.check_fits(trial_path(out_dir), settings, resume)
    if line is not None and notify is not None:
        notify(line)
    trial = Trial(out_dir, settings, resume=resume)
    if notify is not None:
        for notice in trial.notices:
            notify(notice)
    try:
        if trial.finished:
            return trial
        trial.start_iteration = trial.iteration
        start = time.perf_counter()
        trial.run(progress=progress, report=report, every=report_every)
        trial.elapsed = time.perf_counter() - start
    finally:
        trial.close()
    return trial
