"""A trial directory opened for a run, started or resumed, decided here in one place and read
from top to bottom (`open_trial_directory`): a directory of something else is refused, a
trial's is refused without `resume` and with another configuration, a new trial's config.json
is written, and a resumed trial's newest usable checkpoint is restored (its logs checked
first: experiments/run/trial_checks.py), the work past it dropped, and the trial extended if
more iterations are asked for. Called by `Trial` (experiments/run/trial.py) under the
directory's lock, once the trial's room and agent have been built from the config (a config
that builds none leaves the directory as it was)."""

from __future__ import annotations

import contextlib
from pathlib import Path

from experiments import manifest, storage
from experiments.config_file import UnknownSettingError, check_known, with_added_settings
from experiments.file_names import CONFIG_FILE, LOCK_FILE, LOG_DIR
from experiments.log_layout import EXTENSIBLE
from experiments.run import memory_segments
from experiments.run.trial_checks import (
    Restored,
    drop_logs_past,
    is_litter,
    prepare_resume,
    remove_litter,
)
from experiments.run.trial_files import TrialError, move_derived_aside


def refuse_foreign_path(d: Path) -> None:
    """Before anything is written: a file, or a folder of something else, is refused (a
    folder of a new trial killed while writing its first file holds the lock and that
    file's temporary: it is the same command's to use again)."""
    if d.exists() and not d.is_dir():
        raise TrialError(f"{d} is a file, not a directory")
    if d.is_dir() and not (d / CONFIG_FILE).exists():
        if any(p.name != LOCK_FILE and not is_litter(p.name) for p in d.iterdir()):
            raise TrialError(f"{d} is not empty and holds no trial; choose an empty directory")


def open_trial_directory(
    d: Path, config: dict, resume: bool, notices: list[str]
) -> Restored | None:
    """The directory made ready for the run of `config` (the module's docstring). Returns what
    a resume starts from (`prepare_resume`'s), or None to start from iteration 0. Appends to
    `notices` one line per thing a resume did or noticed; TrialError (one line) if the
    directory cannot be used."""
    config_path = d / CONFIG_FILE
    if config_path.exists():
        if not resume:
            raise TrialError(
                f"{d} already holds a trial; add --resume to continue it, or choose a new directory"
            )
        _check_same_configuration(config_path, config)
    try:
        (d / LOG_DIR).mkdir(parents=True, exist_ok=True)
        storage.check_writable(d)
    except OSError as exc:
        raise TrialError(f"cannot write into {d}: {exc.strerror}") from None
    if not config_path.exists():
        _write_first_config(d, config)
    if not resume:
        return None
    restored = prepare_resume(d, config, notices)
    iteration = 0 if restored is None else int(restored[2]["iteration"])
    # The lost work's, past the checkpoint: rewritten by the run.
    drop_logs_past(d, iteration)
    memory_segments.drop_segments_past(d, iteration)
    manifest.drop_past(d, iteration)
    _extend_if_asked(d, config, iteration, notices)
    return restored


def _check_same_configuration(config_path: Path, config: dict) -> None:
    """A resumed trial's config.json holds the same settings as the run's (but those a resume
    may extend)."""
    held = with_added_settings(storage.read_json(config_path))
    try:
        check_known(held, config_path)
    except UnknownSettingError as exc:
        raise TrialError(str(exc)) from None
    diff = [
        f"{key}: {a!r} != {b!r}"
        for key, a, b in storage.config_differences(held, config)
        if key not in EXTENSIBLE
    ]
    if diff:
        raise TrialError(
            f"{config_path.parent} holds a trial of another configuration "
            f"({'; '.join(diff[:4])}); refusing to mix them"
        )


def _write_first_config(d: Path, config: dict) -> None:
    """A new trial's config.json, its first file."""
    remove_litter(d)  # under the lock: a killed first write's (`refuse_foreign_path`)
    try:
        storage.write_json(d / CONFIG_FILE, config)
    except OSError:
        # A new trial whose first file cannot be written (disk full) leaves its folder as it
        # found it, so that the same command can start it later.
        with contextlib.suppress(OSError):
            (d / LOG_DIR).rmdir()  # made just before; empty, or rmdir refuses
        raise


def _extend_if_asked(d: Path, config: dict, iteration: int, notices: list[str]) -> None:
    """More iterations asked than the trial was run with: config.json says so, and what was
    derived from the shorter run is moved aside."""
    config_path = d / CONFIG_FILE
    stored = storage.read_json(config_path)
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
    storage.write_json(config_path, config)
