"""Which trials of a batch have run to their end, for the readers of a batch's logs.

A batch still running (or a trial being extended) holds trials whose logs stop at their last
checkpoint: read beside finished ones they would pass for shorter trials. A trial is finished
when its newest checkpoint says so at the number of iterations its config.json asks for (what
a trial writes last, after its logs: experiments/run/trial.py); its arrays are not read.
"""

from __future__ import annotations

import os
import warnings
from pathlib import Path

from experiments.trial_dir import storage
from experiments.trial_dir.reading import open_for_reading

# Trials named in a warning; more are counted.
NAMED = 5


class IncompleteTrialsWarning(UserWarning):
    """A batch's logs were read while some of its trials had not run to their end."""


def unfinished(trial_dir: str | os.PathLike) -> str | None:
    """None for a trial that ran to its end, else how far it is ("at iteration 200 of 400",
    "no checkpoint yet", "unreadable checkpoint")."""
    trial = open_for_reading(trial_dir)
    try:
        config = trial.config_json()
        total = int(config["trial"]["iterations"])
    except (OSError, storage.CorruptFileError, KeyError, TypeError, ValueError):
        return f"unreadable {trial.config_path.name}"
    if not trial.has_newest_checkpoint():
        return "no checkpoint yet"
    try:
        meta = trial.checkpoint_meta()
        iteration, finished = int(meta["iteration"]), bool(meta["finished"])
    except (storage.CorruptFileError, KeyError, TypeError, ValueError):
        return "unreadable checkpoint"
    return None if finished and iteration == total else f"at iteration {iteration} of {total}"


def unfinished_trials(trial_dirs: list[Path]) -> dict[Path, str]:
    """The trials of `trial_dirs` that have not run to their end, with how far each is."""
    found = {d: unfinished(d) for d in trial_dirs}
    return {d: state for d, state in found.items() if state is not None}


def warn_unfinished(batch_dir: str | os.PathLike, found: dict[Path, str], kept: bool) -> None:
    """Warn (IncompleteTrialsWarning, one line) that the trials in `found` have not run to
    their end, and whether their rows were `kept`."""
    names = [f"{d.name} ({state})" for d, state in sorted(found.items())]
    more = len(names) - NAMED
    shown = "; ".join(names[:NAMED]) + (f"; and {more} more" if more > 0 else "")
    what = (
        "their rows are included" if kept else "left out (include_incomplete=True reads them too)"
    )
    warnings.warn(
        f"{len(found)} trial(s) of {batch_dir} have not run to their end: {shown}; {what}",
        IncompleteTrialsWarning,
        stacklevel=3,
    )
