"""One trial directory of a batch read into the rows of the batch's tables (`trial_rows`): its
eval.json's numbers, its evaluation tables checked against it, the columns of its logs the
report reads, its timing, what its backend declared, and where it was computed and evaluated
(`provenance_rows`). experiments/analysis/results.py collects them over a batch; every refusal
is a `ReportError` (one line naming the file and what to do)."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import pandas as pd

from experiments.analysis.curves import LOG_COLUMNS, curve_rows, tool_numbers
from experiments.analysis.logs import read_log
from experiments.analysis.mechanisms import LOG_COLUMNS as MECHANISM_COLUMNS
from experiments.analysis.mechanisms import trial_mechanisms
from experiments.analysis.report_error import ReportError
from experiments.trial_dir import storage
from experiments.trial_dir.evaluation import Evaluation
from experiments.trial_dir.log_schema import DIVERGED
from experiments.trial_dir.provenance import SHORT_FIELDS
from experiments.trial_dir.reading import CAPABILITIES, open_for_reading, study_reach

COMPETENCE_SCOPES = ("all", "ring1", "ring2", "ring3")


def _read_table(evaluation: Evaluation, kind: str, summary: dict) -> pd.DataFrame | None:
    """The table of `kind` (evaluation.TABLES) of a trial's evaluation, checked against its
    eval.json (`summary`); None for a table that an evaluation from before it existed lacks."""
    try:
        return evaluation.table(kind, summary)
    except storage.CorruptFileError as exc:
        raise ReportError(str(exc).replace("\n", " ")) from None


def evaluation_table(evaluation: Evaluation, kind: str, summary: dict) -> pd.DataFrame:
    """A table every evaluation writes; ReportError if missing or damaged."""
    table = _read_table(evaluation, kind, summary)
    if table is None:
        raise ReportError(
            f"{evaluation.table_path(kind)} is missing: evaluate the trial again (`playroom eval`)"
        )
    return table


def _read_logs(trial_dir: Path) -> tuple[pd.DataFrame, pd.DataFrame]:
    """(iterations log, words log) of a trial; ReportError if unreadable or missing."""
    try:
        # Only what the report reads of the iterations log (its curves, stick numbers and
        # divergences): half the time of reading all of it.
        columns = dict.fromkeys((*LOG_COLUMNS, *MECHANISM_COLUMNS, DIVERGED))
        log = read_log(trial_dir, columns=tuple(columns))
        words = read_log(trial_dir, "words")
    except storage.CorruptFileError as exc:
        raise ReportError(str(exc).replace("\n", " ")) from None
    if log.empty:
        where = open_for_reading(trial_dir).log_folder("iterations").relative_to(trial_dir)
        raise ReportError(f"{trial_dir.name} has no iteration log ({where}/)")
    return log, words


def eval_numbers(path: Path, summary: dict) -> dict[str, float]:
    """A trial's numbers from its eval.json (`summary`, read from `path`)."""
    try:
        vocal = summary["vocal"]
        return {
            **{f"competence_{k}": summary["competence"][k] for k in COMPETENCE_SCOPES},
            "mean_error": summary["mean_error"],
            "mean_random_error": summary["mean_random_error"],
            "share_below_threshold": vocal["share_below_threshold"],
            # null: no voice movement, so no finite distance (experiments/measure/evaluation.py).
            "median_names": _distance(vocal["median_names"]),
            "median_distractors": _distance(vocal["median_distractors"]),
        }
    except (KeyError, TypeError) as exc:
        raise ReportError(
            f"{path} lacks {exc}: evaluate the trial again (`playroom eval`)"
        ) from None


def _distance(value: float | None) -> float:
    return math.inf if value is None else value


def _timing(trial_dir: Path) -> tuple[float, float]:
    """(seconds, iterations) of timing.json; NaN, NaN when the trial did not record it."""
    trial = open_for_reading(trial_dir)
    try:
        timing = trial.timing()
    except storage.CorruptFileError as exc:
        raise ReportError(str(exc)) from None
    if timing is None:
        return math.nan, math.nan
    try:
        return float(timing["seconds"]), float(timing["iterations"])
    except (KeyError, TypeError, ValueError):
        raise ReportError(f"{trial.timing_path} lacks 'seconds' and 'iterations' numbers") from None


def _backend(trial_dir: Path, config: dict) -> dict[str, Any]:
    """What the trial's backend declared (experiments/trial_dir/backend_record.py; older trials:
    from their config): its `reach` (m) and capabilities, what it cannot do by construction."""
    try:
        record = open_for_reading(trial_dir).backend(config)
    except (storage.CorruptFileError, ValueError) as exc:
        raise ReportError(str(exc)) from None
    return {"reach": float(record["reach"]), **{k: bool(record[k]) for k in CAPABILITIES}}


def provenance_rows(d: Path, summary: dict, keys: dict) -> list[dict[str, Any]]:
    """Where a trial was computed (provenance.json) and evaluated (eval.json's
    `evaluated_on`): rows of BatchResults.provenance. Trials from before either was recorded
    have rows of status 'not recorded'; the report counts them as such."""
    rows = [{**keys, "role": "computed", **s} for s in open_for_reading(d).computed_on()]
    evaluated = summary.get("evaluated_on")
    status = "recorded" if isinstance(evaluated, dict) else "not recorded"
    fields = {k: str(evaluated.get(k, "?")) if evaluated else "" for k in SHORT_FIELDS}
    rows.append({**keys, "role": "evaluated", "from_iteration": 0, "status": status, **fields})
    return rows


def trial_rows(
    d: Path, config: dict, summary: dict, label: str, evaluated: Path
) -> tuple[dict[str, Any], pd.DataFrame, pd.DataFrame, pd.DataFrame, pd.DataFrame | None]:
    """(trials row, competence rows, vocal rows, curve rows, the study's test rows or None) of
    one trial directory, whose evaluation lies in `evaluated`."""
    keys = {"trial": d.name, "group": label, "seed": config["trial"]["seed"]}
    trial = open_for_reading(d)
    evaluation = trial.evaluation(evaluated)
    comp = evaluation_table(evaluation, "competence", summary).assign(**keys)
    voc = evaluation_table(evaluation, "vocal", summary).assign(**keys)
    log, words = _read_logs(d)
    reach = study_reach(config["world"])  # one yardstick for every backend
    names = set(voc.loc[voc["is_name"], "word"])
    curve = curve_rows(log, words, config["trial"]["iterations"], names, reach).assign(**keys)
    seconds, timed = _timing(d)
    row = {
        **keys,
        "path": str(d),
        "grasp": config["trial"]["grasp"],
        **_backend(d, config),
        "babbling": config["trial"]["babbling"],
        "iterations": config["trial"]["iterations"],
        "n_placements": summary.get("n_placements"),
        **eval_numbers(trial.evaluation().path, summary),
        "diverged": int(log[DIVERGED].sum()),
        **tool_numbers(log, reach),
        **trial_mechanisms(log, names, set(voc["word"])),
        "seconds": seconds,
        "timed_iterations": timed,
    }
    study = _read_table(evaluation, "study_tests", summary)  # none: evaluated before it
    study = None if study is None else study.assign(**keys)
    return row, comp, voc, curve, study
