"""A trial directory opened for a run, started or resumed, decided here in one place and read
from top to bottom (`open_trial_directory`): the path and the disk checked (the disk by the
run's estimate, experiments/run/estimate.py), a directory of something else refused, the
directory locked, a trial's refused without `resume` and with another configuration, a new
trial's config.json written, and a resumed trial's newest usable checkpoint restored (its logs
checked first and the work past it dropped: resume.py) and the trial extended if more
iterations are asked for. What the run starts from comes back whole (`OpenedTrial`): `Trial`
(experiments/run/trial.py) only takes it. Called once the trial's room and agent have been
built from its typed settings (a config that builds none leaves the directory as it was);
config.json is read once here."""

from __future__ import annotations

import contextlib
import errno
import os
import shutil
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Generic

import numpy as np

from experiments.trial_dir import manifest, memory_segments, storage
from experiments.trial_dir.checkpoint import A, Build, R
from experiments.trial_dir.config_file import (
    EXTENSIBLE,
    UnknownSettingError,
    check_known,
    config_differences,
    source_of,
    trial_identity,
    with_added_settings,
)
from experiments.trial_dir.errors import TrialError, TrialLocked
from experiments.trial_dir.layout import (
    CONFIG_FILE,
    LOCK_FILE,
    LOG_DIR,
    LOG_README,
    LOG_README_FILE,
    STALE_PREFIX,
    TRIAL_ENTRIES,
)
from experiments.trial_dir.lock import DirectoryLock, DirectoryLocked
from experiments.trial_dir.resume import prepare_resume
from experiments.trial_dir.storage import is_litter, remove_litter

# What a trial counts as it runs (its checkpoints keep them; `playroom run` prints them).
COUNTS = ("tool_uses", "words_recognised", "diverged", "stick_returns")


@dataclass
class OpenedTrial(Generic[A, R]):
    """A trial directory ready for its run, locked (`lock`), and what the run starts from:
    the agent and room (restored, or at iteration 0), where the checkpoint left the trial, the
    files its next checkpoint records, and one line per thing the opening did or noticed."""

    dir: Path
    lock: DirectoryLock
    identity: dict  # carried by every checkpoint and log chunk
    source: dict  # first in every log row
    agent: A
    room: R
    best_word_distance: np.ndarray  # to each word, the best reached so far
    counts: dict[str, int]  # of COUNTS
    iteration: int = 0
    memory: memory_segments.MemoryOnDisk = field(
        default_factory=lambda: memory_segments.MemoryOnDisk({}, None, 0)
    )
    # The newest manifest file (experiments/trial_dir/manifest.py), the manifest of the checkpoint
    # restored, and the data files written since it, which the next checkpoint records.
    manifest_pointer: dict | None = None
    recorded: manifest.Manifest | None = None
    unrecorded: list[Path] = field(default_factory=list)
    notices: list[str] = field(default_factory=list)


def open_trial_directory(
    out_dir: str | os.PathLike,
    config: dict,
    parts: tuple[A, R],
    build: Build[A, R],
    resume: bool,
    words: int,
    fits: Callable[[Path], str | None],
) -> OpenedTrial[A, R]:
    """The directory made ready for the run of the trial of `config` (its config.json form;
    `parts`, the agent and room built from it at iteration 0: the run's, or those a resume
    restores into; `build` builds others if a restore fails half-way; `words`, how many words
    its voice has, the best distance to each unreached at first; `fits`, the run's check that
    the trial fits on the directory's disk, before anything is written: TrialError if not, or
    a line to tell the user). TrialError (one line) if the directory cannot be used; the lock
    is held only if the opening succeeds."""
    d = trial_path(out_dir)
    notices = []
    line = fits(d)  # before anything is written
    if line is not None:
        notices.append(line)
    _refuse_foreign_path(d)
    try:
        lock = DirectoryLock.acquired(d)
    except DirectoryLocked as exc:
        raise TrialLocked(str(exc)) from None
    except OSError as exc:
        raise TrialError(f"cannot write into {d}: {exc.strerror}") from None
    try:
        opened = _opened(d, lock, config, parts, build, resume, words)
    except BaseException:
        lock.release()
        raise
    opened.notices[:0] = notices
    return opened


def _opened(
    d: Path,
    lock: DirectoryLock,
    config: dict,
    parts: tuple[A, R],
    build: Build[A, R],
    resume: bool,
    words: int,
) -> OpenedTrial[A, R]:
    config_path = d / CONFIG_FILE
    held = None
    if config_path.exists():
        if not resume:
            raise TrialError(
                f"{d} already holds a trial; add --resume to continue it, or choose a new directory"
            )
        held = storage.read_json(config_path)
        _check_same_configuration(config_path, held, config)
    identity, source = trial_identity(config), source_of(d, config)
    # A resumed trial's files are checked against the record they lie beside, which the run's
    # config was just checked against: the resume needs the directory alone, not the run.
    own = None if held is None else (trial_identity(held), source_of(d, held))
    _ready_to_write(d, config, held is None)
    notices: list[str] = []
    restored = None
    if own is not None:
        restored = prepare_resume(d, *own, parts, build, notices)
    elif resume:
        notices.append(f"{d} holds no checkpoint yet: starting it from iteration 0")
    if restored is None:
        agent, room = parts
        unreached = np.full(words, np.inf)
        counts = dict.fromkeys(COUNTS, 0)
        opened: OpenedTrial[A, R] = OpenedTrial(
            d, lock, identity, source, agent, room, unreached, counts, notices=notices
        )
    else:
        meta = restored.meta
        opened = OpenedTrial(
            d,
            lock,
            identity,
            {**source, "trial": restored.created_as},
            restored.agent,
            restored.room,
            best_word_distance=np.asarray(meta["best_word_distance"], dtype=float),
            counts=dict(meta["counts"]),
            iteration=int(meta["iteration"]),
            memory=restored.memory,
            manifest_pointer=meta.get(manifest.MANIFEST_KEY),
            recorded=restored.recorded,
            unrecorded=restored.unrecorded,
            notices=notices,
        )
        if held is not None:
            _extend_if_asked(d, held, config, opened.iteration, notices)
    readme = d / LOG_DIR / LOG_README_FILE
    if not readme.exists():  # a new trial's, or an old one's moved into the folders
        storage.write_text(readme, LOG_README)
    return opened


def _refuse_foreign_path(d: Path) -> None:
    """Before anything is written: a file, or a folder of something else, is refused (a
    folder of a new trial killed while writing its first file holds the lock and that
    file's temporary: it is the same command's to use again)."""
    if d.exists() and not d.is_dir():
        raise TrialError(f"{d} is a file, not a directory")
    if d.is_dir() and not (d / CONFIG_FILE).exists():
        if any(p.name != LOCK_FILE and not is_litter(p.name) for p in d.iterdir()):
            raise TrialError(f"{d} is not empty and holds no trial; choose an empty directory")


def _check_same_configuration(config_path: Path, held: dict, config: dict) -> None:
    """A resumed trial's config.json (`held`) holds the same settings as the run's (but those
    a resume may extend)."""
    held = with_added_settings(held)
    try:
        check_known(held, config_path)
    except UnknownSettingError as exc:
        raise TrialError(str(exc)) from None
    diff = [
        f"{key}: {a!r} != {b!r}"
        for key, a, b in config_differences(held, config)
        if key not in EXTENSIBLE
    ]
    if diff:
        raise TrialError(
            f"{config_path.parent} holds a trial of another configuration "
            f"({'; '.join(diff[:4])}); refusing to mix them"
        )


def _ready_to_write(d: Path, config: dict, new: bool) -> None:
    """The directory checked writable (TrialError, one line, if not), and a `new` trial's
    config.json written, its first file."""
    try:
        (d / LOG_DIR).mkdir(parents=True, exist_ok=True)
        storage.check_writable(d)
    except OSError as exc:
        raise TrialError(f"cannot write into {d}: {exc.strerror}") from None
    if not new:
        return
    try:
        remove_litter(d)  # under the lock: a killed first write's (`_refuse_foreign_path`)
        storage.write_json(d / CONFIG_FILE, config)
    except OSError:
        # A new trial whose first file cannot be written (disk full) leaves its folder as it
        # found it, so that the same command can start it later.
        with contextlib.suppress(OSError):
            (d / LOG_DIR).rmdir()  # made just before; empty, or rmdir refuses
        raise


def _extend_if_asked(
    d: Path, stored: dict, config: dict, iteration: int, notices: list[str]
) -> None:
    """More iterations asked than the trial (config.json: `stored`) was run with: config.json
    says so, and what was derived from the shorter run is moved aside."""
    asked, stored_total = config["trial"]["iterations"], stored["trial"]["iterations"]
    if asked == stored_total:
        return
    if asked < iteration:
        raise TrialError(
            f"{d} holds {iteration} iterations already; --iterations {asked} would shorten it"
        )
    moved = move_derived_aside(d, iteration)
    if moved:
        notices.append(f"extended from {stored_total} to {asked} iterations; {moved}")
    storage.write_json(d / CONFIG_FILE, config)


def trial_path(out_dir: str | os.PathLike) -> Path:
    """`out_dir` as a Path, if it can name a directory; TrialError (one line) for a symbolic
    link loop, which no directory can be made or found at."""
    path = Path(out_dir)
    try:
        path.resolve()  # Python 3.11 raises RuntimeError on a loop
        path.stat()  # later versions resolve it as it is: the system says ELOOP
    except FileNotFoundError:  # a trial to be made: its folder is created by the run
        pass
    except (RuntimeError, OSError) as exc:
        if isinstance(exc, RuntimeError) or exc.errno == errno.ELOOP:
            raise TrialError(
                f"{path} cannot be used: it is a symbolic link loop (a link that leads back to "
                "itself); choose another directory"
            ) from None
        # Anything else (a parent that is a file, no permission) is said where it is used.
    return path


def move_derived_aside(trial_dir: Path, iteration: int) -> str | None:
    """Move what was derived from a trial at `iteration` (its evaluation, timing, videos) into
    `stale-at-<iteration>/`, before the trial is extended; what was moved, in words, or None."""
    stale = trial_dir / f"{STALE_PREFIX}{iteration:08d}"
    # Neither the trial's own files, nor earlier stale ones, nor a temporary file of a writer
    # (one `remove_litter` spared): none is a result derived from the trial.
    derived = [
        p
        for p in trial_dir.iterdir()
        if p.name not in TRIAL_ENTRIES
        and not p.name.startswith(STALE_PREFIX)
        and storage.temporary_writer(p.name) is None
    ]
    if not derived:
        return None
    stale.mkdir(exist_ok=True)
    for path in derived:
        shutil.move(path, stale / path.name)
    return f"the shorter run's {', '.join(sorted(p.name for p in derived))} moved to {stale.name}/"
