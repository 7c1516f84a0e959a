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
import os
from pathlib import Path

from experiments.analysis.results import BatchResults, ReportError
from experiments.analysis.results import collect as collect_own
from experiments.trial_dir import storage
from experiments.trial_dir.eval_worlds import EVAL_WORLDS, OWN, EvalWorldError
from experiments.trial_dir.evaluation import Evaluation, world_remedy
from experiments.trial_dir.reading import TrialReading, open_for_reading, trials_in

# Trials named in a refusal; more are counted.
NAMED = 3


def _config(trial: TrialReading) -> dict:
    """A trial's config.json, added settings filled in; ReportError if it cannot be read."""
    try:
        config = trial.config_json()
    except (OSError, storage.CorruptFileError) as exc:
        raise ReportError(" ".join(str(exc).split())) from None
    if not isinstance(config, dict) or not isinstance(config.get("world"), dict):
        raise ReportError(f"{trial.config_path} holds no trial's settings")
    return trial.config()


def _evaluation(trial: TrialReading, world: str) -> Evaluation:
    """`TrialReading.evaluation_in`, ReportError for a trial that cannot be tested in `world`."""
    try:
        return trial.evaluation_in(world)
    except EvalWorldError as exc:
        raise ReportError(f"{trial.dir}: {exc}") from None


def _checked(trial: TrialReading, config: dict, world: str) -> Path:
    """The folder of a trial's evaluation in `world`, its eval.json and tables checked."""
    evaluation = _evaluation(trial, world)
    if evaluation.folder == trial.dir:  # its own evaluation: results.collect checks it as ever
        return evaluation.folder
    try:
        summary = evaluation.summary(config, world_remedy(trial.dir, world))
        evaluation.check_world(config, world, summary)
    except storage.CorruptFileError as exc:
        raise ReportError(" ".join(str(exc).split())) from None
    return evaluation.folder


def collect(batch_dir: str | os.PathLike, world: str) -> BatchResults:
    """Every trial of a batch directory as tested in eval world `world` (OWN: their own
    evaluations, `results.collect`), read into tables. ReportError (one line) for an unknown
    world, trials lacking that evaluation (named, with the command that makes it), a damaged
    or stale one, and whatever `results.collect` refuses."""
    batch_dir = Path(batch_dir)
    if world != OWN and world not in EVAL_WORLDS:
        raise ReportError(f"unknown eval world {world!r}: one of {', '.join((OWN, *EVAL_WORLDS))}")
    dirs = trials_in(batch_dir) if batch_dir.is_dir() else []
    if world == OWN or not dirs:  # no trials: said as results.collect says it
        return collect_own(batch_dir)
    opened = {d: open_for_reading(d) for d in dirs}
    configs = {d: _config(opened[d]) for d in dirs}
    missing = [d for d in dirs if not _evaluation(opened[d], world).exists()]
    if missing:
        shown = ", ".join(d.name for d in missing[:NAMED])
        more = f" and {len(missing) - NAMED} more" if len(missing) > NAMED else ""
        where = opened[missing[0]].evaluation_elsewhere(world).path.relative_to(missing[0])
        raise ReportError(
            f"{len(missing)} of {len(dirs)} trials in {batch_dir} have no evaluation in the "
            f"{world} world ({where}): {shown}{more}; "
            f'{world_remedy(missing[0], world)} (a batch: "eval_worlds": ["{world}"] in its '
            "config, then `playroom batch` again)"
        )
    folders = {d: _checked(opened[d], configs[d], world) for d in dirs}
    results = collect_own(batch_dir, eval_dir=lambda d: folders[d])
    tested = results.trials["trial"].map(lambda name: batch_dir / name)
    trials = results.trials.assign(
        eval_world=world,
        tested_grasp=EVAL_WORLDS[world].grasp,
        tested_in_own_world=[folders[d] == d for d in tested],
    )
    return dataclasses.replace(results, trials=trials)
