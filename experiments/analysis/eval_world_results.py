"""A batch's final agents as tested in one eval world, read into tables.

`collect(batch_dir, world)` is `experiments.analysis.results.collect` reading each trial's
evaluation in eval world `world` (experiments/trial_dir/eval_worlds.py) instead of its own: the same
`BatchResults` (competence per test and per trial, all rings and ring by ring, strategies,
words, the study's tests), so that agents of both backends can be compared in one test world.
A trial whose own world that is reads its own evaluation (eval.json in the trial directory);
the others read `eval-in-<world>/`, refused in one line (ReportError) when missing, damaged
(an eval.json not as it recorded itself or of another trial, experiments/trial_dir/eval_record.py; a
table whose size or checksum is not what its eval.json lists), or made for another world
than the one declared now; the message names the command that makes it. The trials' rows say
where they were tested (`eval_world`, `tested_grasp`, `tested_in_own_world`).
"""

from __future__ import annotations

import dataclasses
import json
import os
from pathlib import Path

from experiments.analysis.results import BatchResults, ReportError
from experiments.analysis.results import collect as collect_own
from experiments.trial_dir import eval_record, manifest, storage
from experiments.trial_dir.config_file import with_added_settings
from experiments.trial_dir.eval_worlds import (
    EVAL_WORLDS,
    OWN,
    SWITCHES,
    EvalWorldError,
    own_world,
    world_record,
)
from experiments.trial_dir.layout import (
    CONFIG_FILE,
    EVAL_FILE,
    EVALUATION_TABLES,
    eval_world_dir,
    is_trial_dir,
)

# Trials named in a refusal; more are counted.
NAMED = 3


class EvalWorldMismatch(storage.CorruptFileError):
    """An evaluation folder of a trial made for another eval world, or as another declaration
    of it than the one in experiments/trial_dir/eval_worlds.py now (one line)."""


def remedy(trial_dir: Path, world: str) -> str:
    """The command that (re)makes a trial's evaluation in `world`."""
    return f"`playroom eval {trial_dir} --world {world}` evaluates it there"


def evaluation_dir(trial_dir: Path, config: dict, world: str) -> Path:
    """Where a trial's evaluation in eval world `world` (or OWN) lies: the trial directory
    for its own world, else its `eval-in-<world>/`. `config`: its config.json, added settings
    filled in. EvalWorldError for a world unknown or a config that names no preset."""
    if world == OWN or own_world(config, world):
        return Path(trial_dir)
    return Path(trial_dir) / eval_world_dir(world)


def check_evaluation(trial_dir: Path, config: dict, world: str, summary: dict) -> None:
    """storage.CorruptFileError (one line, with `remedy`) unless `summary`, the eval.json of
    the trial's `eval-in-<world>/`, records `world` as declared now and lists every table of
    an evaluation, each as it lies there (size and SHA-256)."""
    folder = Path(trial_dir) / eval_world_dir(world)
    how = remedy(trial_dir, world)
    # What makes the world: a world setting added to the project later (and filled in for
    # older files, experiments/trial_dir/config_file.py) does not make an evaluation stale.
    expected = json.loads(json.dumps(_identity(world_record(config, world))))
    recorded = summary.get("eval_world")
    if not isinstance(recorded, dict) or _identity(recorded) != expected:
        raise EvalWorldMismatch(
            f"{folder / EVAL_FILE} is not an evaluation in the {world} world as declared now "
            f"(experiments/trial_dir/eval_worlds.py): {how}"
        )
    listed = summary.get(manifest.EVAL_FILES_KEY)
    for name in EVALUATION_TABLES:
        try:
            size, sha256 = listed[name]  # type: ignore[index]
            recorded = manifest.Manifest(folder, {name: manifest.Entry(int(size), str(sha256))}, 0)
        except (KeyError, TypeError, ValueError):
            raise manifest.DamagedFileError(
                f"{folder / EVAL_FILE} does not list {name}: {how}"
            ) from None
        recorded.read_bytes(folder / name, how)


def _identity(record: dict) -> dict:
    """What makes an eval world of a world record: its name, backend and switches."""
    world = record.get("world")
    switches = {s: world.get(s) for s in SWITCHES} if isinstance(world, dict) else None
    return {"name": record.get("name"), "grasp": record.get("grasp"), "switches": switches}


def _config(trial_dir: Path) -> dict:
    try:
        config = storage.read_json(trial_dir / CONFIG_FILE)
    except (OSError, storage.CorruptFileError) as exc:
        raise ReportError(" ".join(str(exc).split())) from None
    if not isinstance(config, dict) or not isinstance(config.get("world"), dict):
        raise ReportError(f"{trial_dir / CONFIG_FILE} holds no trial's settings")
    return with_added_settings(config)


def _folder(trial_dir: Path, config: dict, world: str) -> Path:
    """`evaluation_dir`, ReportError for a trial that cannot be tested in `world`."""
    try:
        return evaluation_dir(trial_dir, config, world)
    except EvalWorldError as exc:
        raise ReportError(f"{trial_dir}: {exc}") from None


def _checked(trial_dir: Path, config: dict, world: str) -> Path:
    """The folder of a trial's evaluation in `world`, its eval.json and tables checked."""
    folder = _folder(trial_dir, config, world)
    if folder == trial_dir:  # its own evaluation: results.collect checks it as ever
        return folder
    try:
        summary = eval_record.read_evaluation(folder, config, remedy(trial_dir, world))
        check_evaluation(trial_dir, config, world, summary)
    except storage.CorruptFileError as exc:
        raise ReportError(" ".join(str(exc).split())) from None
    return folder


def collect(batch_dir: str | os.PathLike, world: str) -> BatchResults:
    """Every trial of a batch directory as tested in eval world `world` (OWN: their own
    evaluations, `results.collect`), read into tables. ReportError (one line) for an unknown
    world, trials lacking that evaluation (named, with the command that makes it), a damaged
    or stale one, and whatever `results.collect` refuses."""
    batch_dir = Path(batch_dir)
    if world != OWN and world not in EVAL_WORLDS:
        raise ReportError(f"unknown eval world {world!r}: one of {', '.join((OWN, *EVAL_WORLDS))}")
    listed = batch_dir.iterdir() if batch_dir.is_dir() else iter(())
    dirs = sorted(d for d in listed if d.is_dir() and is_trial_dir(d))
    if world == OWN or not dirs:  # no trials: said as results.collect says it
        return collect_own(batch_dir)
    configs = {d: _config(d) for d in dirs}
    missing = [d for d in dirs if not (_folder(d, configs[d], world) / EVAL_FILE).exists()]
    if missing:
        shown = ", ".join(d.name for d in missing[:NAMED])
        more = f" and {len(missing) - NAMED} more" if len(missing) > NAMED else ""
        raise ReportError(
            f"{len(missing)} of {len(dirs)} trials in {batch_dir} have no evaluation in the "
            f"{world} world ({eval_world_dir(world)}/{EVAL_FILE}): {shown}{more}; "
            f'{remedy(missing[0], world)} (a batch: "eval_worlds": ["{world}"] in its '
            "config, then `playroom batch` again)"
        )
    folders = {d: _checked(d, configs[d], world) for d in dirs}
    results = collect_own(batch_dir, eval_dir=lambda d: folders[d])
    tested = results.trials["trial"].map(lambda name: batch_dir / name)
    trials = results.trials.assign(
        eval_world=world,
        tested_grasp=EVAL_WORLDS[world].grasp,
        tested_in_own_world=[folders[d] == d for d in tested],
    )
    return dataclasses.replace(results, trials=trials)
