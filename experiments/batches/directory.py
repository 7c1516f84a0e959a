"""A batch directory belongs to one batch: a rerun into it with other settings is refused, in
one line naming the differences, before anything is written or any cluster started.

What the directory holds is checked twice: its record (batch.json) against the spec asked for,
field by field (seeds may be added, since the trials of the seeds already run stay what the
batch would run; nothing else may change, not even the order-free lists' members), then every
trial directory in it against the config the batch would give that trial, so that a directory
whose record was lost, or holds trials of an earlier record, cannot mix either."""

from __future__ import annotations

import dataclasses
import json
from pathlib import Path

from experiments.batch_files import BATCH_FILE
from experiments.batches.spec import BatchError, BatchSpec, spec_record
from experiments.run.trial_config import full_config
from experiments.trial_dir import storage
from experiments.trial_dir.config_file import config_differences, with_added_settings
from experiments.trial_dir.reading import TRIAL_MARKS, is_trial, open_for_reading, trials_in

# Fields compared as sets: their order changes only the order trials are listed in.
_SETS = ("grasps", "babbling", "seeds")
# Not a setting: a rerun may describe the batch in other words, and ask for other eval worlds
# (the trials stay what they are; each world's evaluation is derived from them, beside them).
_FREE = ("description", "eval_worlds")
# Config keys a trial may hold otherwise and still be the batch's: the release that wrote it
# (a checkpoint's identity leaves it out too: experiments/trial_dir/config_file.py).
_NOT_SETTINGS = ("package_version",)
# Trials named in a refusal; more are counted.
NAMED = 3


def _shown(value: object) -> str:
    """A setting's value in a message: strings bare, the rest as compact JSON, shortened."""
    text = value if isinstance(value, str) else json.dumps(value, separators=(", ", ": "))
    return text if len(text) <= 40 else text[:37] + "..."


def _defaults() -> dict:
    """Every field's default as a record holds it: a field an older record lacks ran so."""
    return spec_record(BatchSpec())


def record_differences(record: dict, spec: BatchSpec) -> list[tuple[str, object, object]]:
    """(field, recorded, asked) of every setting where `spec` is another batch than the one
    `record` (batch.json) describes; seeds only where some recorded seed is left out."""
    asked, defaults = spec_record(spec), _defaults()
    out: list[tuple[str, object, object]] = []
    for name in asked:
        if name in _FREE:
            continue
        had = record.get(name, defaults[name])
        now = asked[name]
        if name == "seeds" and isinstance(had, list):
            if not set(map(json.dumps, had)) <= set(map(json.dumps, now)):
                out.append((name, had, now))
        elif name in _SETS and isinstance(had, list):
            if sorted(map(json.dumps, had)) != sorted(map(json.dumps, now)):
                out.append((name, had, now))
        elif had != now:
            out.append((name, had, now))
    return out


def _check_record(spec: BatchSpec, out: Path) -> None:
    path = out / BATCH_FILE
    if not path.exists():
        return  # a new batch, or one from before batch.json: its trials are checked below
    try:
        record = storage.read_json(path)
    except (OSError, storage.CorruptFileError) as exc:
        raise BatchError(
            f"cannot read {path}, which says what batch {out} is ({' '.join(str(exc).split())}); "
            "remove it to have the trials checked against this run, or use another --out"
        ) from None
    if not isinstance(record, dict):
        raise BatchError(f"{path} is not a batch record; remove it or use another --out")
    differences = record_differences(record, spec)
    if differences:
        had = ", ".join(f"{n}={_shown(a)}" for n, a, _ in differences)
        now = ", ".join(f"{n}={_shown(b)}" for n, _, b in differences)
        seeds = any(name == "seeds" for name, _, _ in differences)
        why = " (seeds may be added, not left out)" if seeds else ""
        raise BatchError(
            f"batch {out} was made with {had}, this run asks {now}{why}; use another --out"
        )


def _names(names: list[str]) -> str:
    more = len(names) - NAMED
    return ", ".join(names[:NAMED]) + (f" and {more} more" if more > 0 else "")


def _difference(trial_dir: Path, wanted: dict, placements: int) -> str | None:
    """How a trial directory differs from what the batch would write there (`wanted`, its
    config.json; `placements`, its evaluation's), the setting asked for first; None when it
    does not, or when its files cannot be read (its own task then reports the damage)."""
    trial = open_for_reading(trial_dir)
    try:
        held = trial.config_json()
    except (OSError, storage.CorruptFileError):
        return None
    held = with_added_settings(held) if isinstance(held, dict) else {}
    differences = sorted(
        ((k, a, b) for k, a, b in config_differences(held, wanted) if k not in _NOT_SETTINGS),
        key=lambda d: not d[0].startswith("trial."),  # the setting asked for, not its effects
    )
    if differences:
        k, a, b = differences[0]
        return f"{trial_dir.name} was run with {k}={_shown(a)}, this batch runs {_shown(b)}"
    try:  # an evaluation at the trial's end would be kept as the batch's (runner.is_complete)
        summary = trial.evaluation().summary(held, "", warn=False)
    except (OSError, KeyError, TypeError, storage.CorruptFileError):
        return None  # not kept: evaluated again
    at, n = summary.get("evaluated_at_iteration"), summary.get("n_placements")
    if at == wanted["trial"]["iterations"] and n is not None and n != placements:
        return (
            f"{trial_dir.name} was evaluated with eval_placements={n}, this batch uses {placements}"
        )
    return None


def _check_trials(spec: BatchSpec, out: Path) -> None:
    trials = dict(spec.trials())
    present = trials_in(out)
    foreign = [d.name for d in present if d.name not in trials]
    if foreign:
        raise BatchError(
            f"{out} holds trials this batch does not run: {_names(foreign)}; use another --out"
        )
    # One config per grasp and babbling mode (building one loads the MJCF): seeds differ only
    # in trial.seed.
    expected: dict[tuple[str, str], dict] = {}
    found: dict[str, str] = {}
    for d in present:
        settings = trials[d.name]
        key = (settings.grasp, settings.babbling)
        if key not in expected:
            expected[key] = full_config(dataclasses.replace(settings, seed=0))
        wanted = json.loads(json.dumps(expected[key]))
        wanted["trial"]["seed"] = settings.seed
        difference = _difference(d, wanted, spec.eval_placements)
        if difference is not None:
            found[d.name] = difference
    if found:
        names = list(found)
        others = f" ({len(names)} trials disagree: {_names(names)})" if len(names) > 1 else ""
        raise BatchError(f"{out}: {found[names[0]]}{others}; use another --out")


def check_directory(spec: BatchSpec, out: Path) -> None:
    """BatchError (one line) unless `out` is new, or holds this batch: its record and every
    trial it holds are what `spec` would write (a trial directory itself is no batch's).
    Reads only."""
    if not out.is_dir():
        return
    if is_trial(out):
        raise BatchError(
            f"{out} is a trial directory (it holds {TRIAL_MARKS}), not a batch's: give the "
            "batch a directory of its own"
        )
    _check_record(spec, out)
    _check_trials(spec, out)
