"""One trial: the Model Babbling agent playing in one room, written to a directory that
survives being killed.

A trial directory holds:
- `config.json`: every setting (trial, world, voice, learner), the package version, the seed;
- `checkpoint.npz`: agent memory, room state and every random generator state, rewritten
  every `checkpoint_every` iterations and at the end, with the one before it kept beside it
  as `checkpoint.prev.npz`: a damaged newest checkpoint costs at most two periods;
- `log/iterations-NNNNNNNN.parquet`: one row per iteration (motor space, chosen model, events),
  one file per checkpoint period, starting at iteration NNNNNNNN;
- `log/words-NNNNNNNN.parquet`: every 100 iterations, the best distance reached so far to each
  of the 6 words.
Each file is written atomically, and a log chunk is always written before the checkpoint that
covers it, so a run killed at any moment resumes from its last checkpoint and rewrites the same
chunks: the final memory and logs equal those of an uninterrupted run.

One process writes into a trial directory at a time (experiments/lock.py). Resuming with more
iterations than the trial was asked for extends it: the result equals a run asked for the
larger number from the start, and files derived from the shorter run (its evaluation) are
moved aside into `stale-at-NNNNNNNN/`.
"""

from __future__ import annotations

import dataclasses
import json
import os
import shutil
import time
from collections.abc import Callable
from dataclasses import dataclass
from importlib.metadata import version
from pathlib import Path

import numpy as np
import pandas as pd
from tqdm import tqdm

from experiments import storage
from experiments.lock import LOCK_FILE, DirectoryLock, DirectoryLocked
from learner.agent import Agent
from learner.config import LearnerConfig
from models.layout import TOYS, block_slice
from sim import Playroom
from sim import events as ev
from sim.config import DEFAULT_WORLD, WorldConfig, config_from_dict
from sim.vocal.config import DEFAULT_VOICE, VoiceConfig
from sim.vocal.words import word_distances

CONFIG_FILE = "config.json"
CHECKPOINT_FILE = "checkpoint.npz"
PREVIOUS_CHECKPOINT_FILE = "checkpoint.prev.npz"
# Where a damaged newest checkpoint is kept when a resume falls back past it.
DAMAGED_CHECKPOINT_FILE = "checkpoint.damaged.npz"
LOG_DIR = "log"
# What a trial directory holds of the trial itself; everything else in it (evaluation, timing,
# videos) was derived from the trial at some iteration and goes stale when it is extended.
TRIAL_ENTRIES = (
    CONFIG_FILE,
    CHECKPOINT_FILE,
    PREVIOUS_CHECKPOINT_FILE,
    DAMAGED_CHECKPOINT_FILE,
    LOG_DIR,
    LOCK_FILE,
)
STALE_PREFIX = "stale-at-"
# Iterations between two rows of the words log (issue 4: "every 100 iterations").
WORDS_LOG_PERIOD = 100
# The agent's random generator is seeded apart from the room's, from the same trial seed.
AGENT_STREAM = 1


class TrialError(Exception):
    """A trial directory or setting that cannot be used; the message says why."""


@dataclass(frozen=True)
class TrialSettings:
    """What a user chooses for one trial (`playroom run`)."""

    grasp: str = "kinematic"
    iterations: int = 1000
    seed: int = 0
    babbling: str = "random"
    checkpoint_every: int = 1000

    def __post_init__(self) -> None:
        if self.grasp not in ("kinematic", "physical"):
            raise TrialError(f"unknown grasp {self.grasp!r}: 'kinematic' or 'physical'")
        for name in ("iterations", "checkpoint_every"):
            value = getattr(self, name)
            if isinstance(value, bool) or not isinstance(value, int) or value <= 0:
                raise TrialError(f"{name} must be a positive integer, got {value!r}")
        if isinstance(self.seed, bool) or not isinstance(self.seed, int) or self.seed < 0:
            raise TrialError(f"seed must be a non-negative integer, got {self.seed!r}")


def full_config(
    settings: TrialSettings,
    world: WorldConfig = DEFAULT_WORLD,
    voice: VoiceConfig = DEFAULT_VOICE,
    learner: LearnerConfig | None = None,
) -> dict:
    """Every setting of a trial, as written to config.json: what `fresh_trial_parts` builds
    the trial's room and agent from."""
    learner = learner or LearnerConfig(babbling=settings.babbling)
    config = {
        "trial": dataclasses.asdict(settings),
        "world": dataclasses.asdict(world),
        "voice": dataclasses.asdict(voice),
        "learner": learner.to_dict(),
        "package_version": version("playroom"),
    }
    # Through JSON and back, so that it compares equal to what config.json holds.
    return json.loads(json.dumps(config))


# Settings a resume may change: a trial can be extended to more iterations.
EXTENSIBLE = ("trial.iterations",)


class TrialLocked(TrialError):
    """Another process is writing into the trial directory."""


class Trial:
    """A trial directory and the loop that fills it. It holds the directory's lock from its
    creation until `close` (or the end of the process)."""

    def __init__(self, out_dir: str | os.PathLike, settings: TrialSettings, resume: bool = False):
        self.dir = Path(out_dir)
        self.settings = settings
        self.config = full_config(settings)
        self.notices: list[str] = []  # one line each: what a resume had to do
        self._refuse_foreign_path()
        try:
            self._lock = DirectoryLock(self.dir).acquire()
        except DirectoryLocked as exc:
            raise TrialLocked(str(exc)) from None
        except OSError as exc:
            raise TrialError(f"cannot write into {self.dir}: {exc.strerror}") from None
        try:
            self._check_directory(resume)
            self.agent, self.room = fresh_trial_parts(self.config)
            self.iteration = 0
            self.best_word_distance = np.full(len(self.room.vocal_tract.config.words), np.inf)
            self.counts = {"tool_uses": 0, "words_recognised": 0, "diverged": 0}
            self.elapsed: float | None = None  # seconds of the last `run_trial`
            self.start_iteration = 0
            if resume:
                self._resume()
        except BaseException:
            self.close()
            raise

    def close(self) -> None:
        """Give up the directory's lock."""
        self._lock.release()

    # Directory rules ----------------------------------------------------------------------
    def _refuse_foreign_path(self) -> None:
        """Before anything is written: a file, or a folder of something else, is refused."""
        d = self.dir
        if d.exists() and not d.is_dir():
            raise TrialError(f"{d} is a file, not a directory")
        if d.is_dir() and not (d / CONFIG_FILE).exists():
            if any(p.name != LOCK_FILE for p in d.iterdir()):
                raise TrialError(f"{d} is not empty and holds no trial; choose an empty directory")

    def _check_directory(self, resume: bool) -> None:
        d = self.dir
        config_path = d / CONFIG_FILE
        if config_path.exists():
            if not resume:
                raise TrialError(
                    f"{d} already holds a trial; add --resume to continue it, or choose a new "
                    "directory"
                )
            diff = [
                f"{key}: {a!r} != {b!r}"
                for key, a, b in storage.config_differences(
                    storage.read_json(config_path), self.config
                )
                if key not in EXTENSIBLE
            ]
            if diff:
                raise TrialError(
                    f"{d} holds a trial of another configuration ({'; '.join(diff[:4])}); "
                    "refusing to mix them"
                )
        try:
            (d / LOG_DIR).mkdir(parents=True, exist_ok=True)
            probe = d / ".write-test"
            probe.write_bytes(b"")
            probe.unlink()
        except OSError as exc:
            raise TrialError(f"cannot write into {d}: {exc.strerror}") from None
        if not config_path.exists():
            storage.write_json(config_path, self.config)

    @property
    def finished(self) -> bool:
        return self.iteration >= self.settings.iterations

    # Checkpoints --------------------------------------------------------------------------
    def _save_checkpoint(self) -> None:
        room_state = self.room.get_state()
        # The agent's state is plain arrays (its config and generator as 0-d JSON strings).
        arrays = {f"agent/{k}": v for k, v in self.agent.state_dict().items()}
        arrays["room/physics"] = room_state.pop("physics")
        arrays["best_word_distance"] = self.best_word_distance
        meta = {
            "iteration": self.iteration,
            "finished": self.finished,
            "room": room_state,
            "counts": self.counts,
        }
        newest = self.dir / CHECKPOINT_FILE
        if newest.exists():
            # Killed between these two lines, the trial still has the previous checkpoint.
            os.replace(newest, self.dir / PREVIOUS_CHECKPOINT_FILE)
        storage.write_arrays(newest, arrays, meta)

    def _resume(self) -> None:
        """Load the newest readable checkpoint, drop the logs past it, and extend the trial
        if more iterations are asked for than it was run with."""
        newest = self.dir / CHECKPOINT_FILE
        previous = self.dir / PREVIOUS_CHECKPOINT_FILE
        if newest.exists() or previous.exists():
            try:
                meta = restore_checkpoint(self.dir, self.agent, self.room)
            except storage.CorruptFileError as exc:
                if not previous.exists():
                    raise
                # A restore that failed half-way may have changed them: start from fresh parts.
                self.agent, self.room = fresh_trial_parts(self.config)
                meta = restore_checkpoint(self.dir, self.agent, self.room, PREVIOUS_CHECKPOINT_FILE)
                if newest.exists():
                    os.replace(newest, self.dir / DAMAGED_CHECKPOINT_FILE)
                self.notices.append(
                    f"{exc}; resumed from the previous checkpoint, at iteration "
                    f"{meta['iteration']} (the damaged one is kept as {DAMAGED_CHECKPOINT_FILE})"
                )
            self.best_word_distance = np.asarray(meta["best_word_distance"], dtype=float)
            self.iteration = int(meta["iteration"])
            self.counts = dict(meta["counts"])
        # Log chunks past the checkpoint belong to the lost work: they are rewritten.
        for chunk in (self.dir / LOG_DIR).glob("*.parquet"):
            if int(chunk.stem.split("-")[1]) >= self.iteration:
                chunk.unlink()
        self._extend_if_asked()

    def _extend_if_asked(self) -> None:
        config_path = self.dir / CONFIG_FILE
        stored = storage.read_json(config_path)
        asked, stored_total = self.settings.iterations, stored["trial"]["iterations"]
        if asked == stored_total:
            return
        if asked < self.iteration:
            raise TrialError(
                f"{self.dir} holds {self.iteration} iterations already; --iterations {asked} "
                "would shorten it"
            )
        stale = self.dir / f"{STALE_PREFIX}{self.iteration:08d}"
        derived = [p for p in self.dir.iterdir() if p.name not in TRIAL_ENTRIES]
        derived = [p for p in derived if not p.name.startswith(STALE_PREFIX)]
        if derived:
            stale.mkdir(exist_ok=True)
            for path in derived:
                shutil.move(path, stale / path.name)
            self.notices.append(
                f"extended from {stored_total} to {asked} iterations; the shorter run's "
                f"{', '.join(sorted(p.name for p in derived))} moved to {stale.name}/"
            )
        storage.write_json(config_path, self.config)

    # The loop -----------------------------------------------------------------------------
    def run(self, progress: bool = True) -> None:
        """Run until `iterations`, checkpointing every `checkpoint_every` iterations."""
        total = self.settings.iterations
        bar = tqdm(
            total=total,
            initial=self.iteration,
            disable=not progress,
            unit="it",
            desc=f"{self.settings.grasp} seed {self.settings.seed}",
            dynamic_ncols=True,
        )
        rows: list[dict] = []
        word_rows: list[dict] = []
        chunk_start = self.iteration
        while self.iteration < total:
            rows.append(self._iterate())
            self.iteration += 1
            if self.iteration % WORDS_LOG_PERIOD == 0:
                word_rows.append(self._word_row())
            bar.update(1)
            if self.iteration % 50 == 0:
                bar.set_postfix(self.counts, refresh=False)
            if self.iteration % self.settings.checkpoint_every == 0 or self.iteration == total:
                self._write_logs(chunk_start, rows, word_rows)
                self._save_checkpoint()
                rows, word_rows, chunk_start = [], [], self.iteration
        bar.set_postfix(self.counts)
        bar.close()

    def _iterate(self) -> dict:
        proposal, _, feedback = self.agent.play(self.room)
        if proposal.motor_space == "voice":
            sound = feedback.s[block_slice("sound")]
            distances = word_distances(sound, self.room.vocal_tract.config)
            np.minimum(self.best_word_distance, distances, out=self.best_word_distance)
        row = log_row(self.iteration, proposal, feedback)
        self.counts["tool_uses"] += sum(row[f"{toy}_moved_by"] == "stick" for toy in TOYS)
        self.counts["words_recognised"] += row["word_recognised"] != ""
        self.counts["diverged"] += row["diverged"]
        return row

    def _word_row(self) -> dict:
        row = {"iteration": self.iteration}
        words = self.room.vocal_tract.config.words
        for word, best in zip(words, self.best_word_distance, strict=True):
            row[word] = float(best)
        return row

    def _write_logs(self, start: int, rows: list[dict], word_rows: list[dict]) -> None:
        log = self.dir / LOG_DIR
        storage.write_table(log / f"iterations-{start:08d}.parquet", pd.DataFrame(rows))
        if word_rows:
            storage.write_table(log / f"words-{start:08d}.parquet", pd.DataFrame(word_rows))


def log_row(iteration: int, proposal, feedback) -> dict:
    """One row of the iterations log: what was tried and what happened."""
    row = {
        "iteration": iteration,
        "motor_space": proposal.motor_space,
        "model": -1 if proposal.model is None else int(proposal.model),
        "stick_grasped": False,
        "stick_moved_by": "",
        **{f"{toy}_moved_by": "" for toy in TOYS},
        "word_recognised": "",
        "caregiver_said": "",
        "diverged": False,
    }
    for e in feedback.events:
        if e.kind == ev.STICK_GRASPED:
            row["stick_grasped"] = True
        elif e.kind == ev.STICK_MOVED:
            row["stick_moved_by"] = e.by
        elif e.kind == ev.TOY_MOVED:
            row[f"{e.obj}_moved_by"] = e.by
        elif e.kind == ev.WORD_RECOGNISED:
            row["word_recognised"] = e.word
        elif e.kind == ev.CAREGIVER_SAID:
            row["caregiver_said"] = e.word
        elif e.kind == ev.DIVERGED:
            row["diverged"] = True
    return row


def fresh_trial_parts(config: dict) -> tuple[Agent, Playroom]:
    """The agent and room of a trial's iteration 0, as its config makes them."""
    settings = config["trial"]
    room = Playroom(
        grasp=settings["grasp"],
        seed=settings["seed"],
        config=config_from_dict(WorldConfig, config["world"]),
        voice=config_from_dict(VoiceConfig, config["voice"]),
    )
    agent = Agent(
        LearnerConfig.from_dict(config["learner"]),
        np.random.default_rng([settings["seed"], AGENT_STREAM]),
    )
    return agent, room


def restore_checkpoint(
    trial_dir: str | os.PathLike, agent: Agent, room: Playroom, name: str = CHECKPOINT_FILE
) -> dict:
    """Load a trial's checkpoint into `agent` and `room`; returns the checkpoint's metadata
    with 'best_word_distance' added. CorruptFileError if it cannot be read or restored."""
    path = Path(trial_dir) / name
    if not path.exists():
        raise storage.CorruptFileError(f"{path} is missing")
    arrays, meta = storage.read_arrays(path)
    try:
        agent_state = {
            k.removeprefix("agent/"): v for k, v in arrays.items() if k.startswith("agent/")
        }
        agent.load_state_dict(agent_state)
        room.set_state({**meta["room"], "physics": arrays["room/physics"]})
        meta["best_word_distance"] = arrays["best_word_distance"].copy()
    except (KeyError, ValueError, TypeError) as exc:
        raise storage.CorruptFileError(f"{path} cannot be restored ({exc})") from None
    return meta


def load_trial(trial_dir: str | os.PathLike) -> tuple[dict, Agent, Playroom, dict]:
    """A finished or checkpointed trial, read-only: (config, agent, room, checkpoint meta)."""
    trial_dir = Path(trial_dir)
    if not (trial_dir / CONFIG_FILE).exists():
        raise TrialError(f"{trial_dir} holds no trial ({CONFIG_FILE} is missing)")
    if not any((trial_dir / n).exists() for n in (CHECKPOINT_FILE, PREVIOUS_CHECKPOINT_FILE)):
        raise TrialError(f"{trial_dir} has no checkpoint yet")
    config = storage.read_json(trial_dir / CONFIG_FILE)
    agent, room = fresh_trial_parts(config)
    try:
        meta = restore_checkpoint(trial_dir, agent, room)
    except storage.CorruptFileError as exc:
        if (trial_dir / PREVIOUS_CHECKPOINT_FILE).exists():
            raise storage.CorruptFileError(
                f"{exc}; `playroom run --resume` continues from the previous checkpoint"
            ) from None
        raise
    return config, agent, room, meta


def read_log(trial_dir: str | os.PathLike, kind: str = "iterations") -> pd.DataFrame:
    """All chunks of one log ('iterations' or 'words') of a trial, in order."""
    chunks = sorted((Path(trial_dir) / LOG_DIR).glob(f"{kind}-*.parquet"))
    if not chunks:
        return pd.DataFrame()
    return pd.concat([storage.read_table(c) for c in chunks], ignore_index=True)


def run_trial(
    out_dir: str | os.PathLike,
    settings: TrialSettings,
    resume: bool = False,
    progress: bool = True,
    notify: Callable[[str], None] | None = None,
) -> Trial:
    """Create (or resume) a trial in out_dir and run it to the end. `notify` is called, before
    the run, with each line a resume has to report (a fallback checkpoint, an extension)."""
    trial = Trial(out_dir, settings, resume=resume)
    for notice in trial.notices if notify is not None else ():
        notify(notice)
    try:
        if trial.finished:
            return trial
        trial.start_iteration = trial.iteration
        start = time.perf_counter()
        trial.run(progress=progress)
        trial.elapsed = time.perf_counter() - start
    finally:
        trial.close()
    return trial
