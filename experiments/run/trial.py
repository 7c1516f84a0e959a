"""One trial: the Model Babbling agent playing in one room, written to a directory that
survives being killed (its files: experiments/trial_dir/layout.py).

Each file is written atomically, and a log chunk, like the segment of the memory's new rows
(experiments/trial_dir/memory_segments.py), is always written before the checkpoint that covers it,
so a run killed at any moment resumes from its last checkpoint and rewrites the same chunks and
segments: the final memory and logs equal those of an uninterrupted run.

One process writes into a trial directory at a time (experiments/trial_dir/lock.py). Resuming with
more iterations than the trial was asked for extends it: the result equals a run asked for the
larger number from the start, and files derived from the shorter run (its evaluation) are moved
aside into `stale-at-NNNNNNNN/`.
"""

from __future__ import annotations

import functools
import os
import time
from collections.abc import Callable

import numpy as np
import pandas as pd
from tqdm import tqdm

from experiments.run import estimate, progress_bar, stop_requests
from experiments.run.settings import TrialSettings
from experiments.run.trial_config import typed_config
from experiments.run.trial_parts import learner_values, log_row, trial_parts
from experiments.trial_dir.log_schema import LEARNER_COLUMNS, LEARNER_DTYPE, WORDS_LOG_PERIOD
from experiments.trial_dir.writing import Declared, OpenedTrial, open_for_writing
from learner.agent import Agent
from models.layout import TOYS, block_slice
from sim import Playroom

_SOUND = block_slice("sound")
_TOY_MOVED_BY = tuple(f"{toy}_moved_by" for toy in TOYS)


class Trial:
    """A trial directory and the loop that fills it. It holds the directory's lock from its
    creation until `close` (or the end of the process).

    Its opening reads from top to bottom: the settings typed once, the room and agent built
    from them (before anything is written: a config that makes no room or agent leaves the
    directory as it was), the directory opened (experiments/trial_dir/opening.py: checked,
    locked, config.json written or compared, a resume's checkpoint restored into those parts),
    who computes recorded (provenance.json), what the backend declares recorded
    (backend.json)."""

    def __init__(self, out_dir: str | os.PathLike, settings: TrialSettings, resume: bool = False):
        self.settings = settings
        typed = typed_config(settings)  # the settings typed once, here
        self.config = typed.json
        # Built before anything is written; a resume restores into them (and builds others if a
        # restore fails half-way).
        build = functools.partial(
            trial_parts, settings.grasp, settings.seed, typed.world, typed.voice, typed.learner
        )
        parts = build()
        words = len(parts[1].vocal_tract.config.words)
        fits = functools.partial(estimate.check_fits, settings=settings, resume=resume)
        backend = parts[1].backend
        declared = Declared(
            parts[1].vocal_tract.data_record(),  # with the machine, provenance.json
            backend.name,  # and what it declares, backend.json: both of the config
            backend.reach(),
            backend.capabilities(),
        )
        # Held from here: `close` gives it up.
        self.writer = open_for_writing(
            out_dir, self.config, parts, build, resume, words, fits, declared
        )
        self._take(self.writer.opened)

    def _take(self, opened: OpenedTrial[Agent, Playroom]) -> None:
        """Where the run starts: what the opening returned."""
        self.dir, self.notices = opened.dir, opened.notices
        self.agent, self.room = opened.agent, opened.room
        self.iteration = opened.iteration
        self.best_word_distance, self.counts = opened.best_word_distance, opened.counts
        self.elapsed: float | None = None  # seconds of the last `run_trial`
        self.start_iteration = self.iteration

    def close(self) -> None:
        """Give up the directory's lock."""
        self.writer.close()

    @property
    def finished(self) -> bool:
        return self.iteration >= self.settings.iterations

    # Checkpoints --------------------------------------------------------------------------
    def _save_checkpoint(self, logs: dict | None = None) -> None:
        """The checkpoint at the iteration reached, with the period's `logs` (`_logs`)."""
        self.writer.save_checkpoint(
            self.agent,
            self.room,
            self.iteration,
            self.finished,
            self.counts,
            self.best_word_distance,
            logs,
        )

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
        if self.iteration == 0 and not self.writer.has_checkpoint():
            # A checkpoint before the first log chunk: a directory with logs then always has
            # a checkpoint, unless it was lost, and a resume can tell which
            # (experiments/trial_dir/resume.py, `prepare_resume`).
            self._save_checkpoint()
        rows: list[tuple[dict, np.ndarray]] = []
        word_rows: list[dict] = []
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
                self._save_checkpoint(self._logs(rows, word_rows))
                rows, word_rows = [], []

    def _iterate(self) -> tuple[dict, np.ndarray]:
        """One iteration: its row of events (`log_row`) and its learner's values."""
        interests = self.agent.interests()  # what this iteration's model was chosen from
        proposal, context, feedback = self.agent.play(self.room)
        reached = self.agent.outcome(proposal, feedback.s)
        if proposal.motor_space == "voice":
            sound = feedback.s[_SOUND]
            distances = self.room.vocal_tract.word_distances(sound)
            np.minimum(self.best_word_distance, distances, out=self.best_word_distance)
        row = log_row(self.iteration, proposal, feedback, context)
        self.counts["tool_uses"] += sum(row[column] == "stick" for column in _TOY_MOVED_BY)
        self.counts["words_recognised"] += row["word_recognised"] != ""
        self.counts["diverged"] += row["diverged"]
        self.counts["stick_returns"] += row["stick_returned"]
        return row, learner_values(proposal, reached, interests)

    def _word_row(self) -> dict:
        row: dict[str, float] = {"iteration": self.iteration}
        words = self.room.vocal_tract.config.words
        for word, best in zip(words, self.best_word_distance, strict=True):
            row[word] = float(best)
        return row

    @staticmethod
    def _logs(rows: list[tuple[dict, np.ndarray]], word_rows: list[dict]) -> dict:
        """A period's logs, as the writer takes them: kind -> (rows, columns written plain)."""
        events = pd.DataFrame([row for row, _ in rows])
        values = np.vstack([v for _, v in rows]).astype(LEARNER_DTYPE)
        learner = pd.DataFrame(values, columns=list(LEARNER_COLUMNS))
        logs = {"iterations": (pd.concat([events, learner], axis=1), LEARNER_COLUMNS)}
        if word_rows:
            logs["words"] = (pd.DataFrame(word_rows), ())
        return logs


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
    A trial that will not fit on its disk is refused before anything is written (TrialError);
    a long one is told to `notify`, first, with its expected time and disk
    (experiments/run/estimate.py)."""
    trial = Trial(out_dir, settings, resume=resume)
    if notify is not None:
        for notice in trial.notices:
            notify(notice)
    try:
        if trial.finished:
            return trial
        start = time.perf_counter()
        trial.run(progress=progress, report=report, every=report_every)
        trial.elapsed = time.perf_counter() - start
    finally:
        trial.close()
    return trial
