"""A batch directory read into tables (`collect`): one row per trial, test, word or curve point.

A batch directory holds trial directories (any sub-directory with `config.json`), each
evaluated (`eval.json`, `competence.parquet`, `vocal.parquet`, written by
`experiments.measure.evaluation`). Trials form groups by grasp backend and babbling mode; within a
group every setting but the seed must agree, or collecting refuses to pool them.

Every refusal is a `ReportError` whose message is one line naming the trial and what to do, so
that the CLI can print it as it is.
"""

from __future__ import annotations

import dataclasses
import os
import warnings
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import pandas as pd

from experiments.analysis.batch_checks import BatchMismatch, check_group, group_label, shared_config
from experiments.analysis.batch_record import RecordMismatch, check_trials_agree
from experiments.analysis.report_error import ReportError
from experiments.analysis.trial_rows import provenance_rows, trial_rows
from experiments.trial_dir import storage
from experiments.trial_dir.config_file import with_added_settings
from experiments.trial_dir.reading import (
    SCENES_KEY,
    TRIAL_MARKS,
    UncheckedTrialWarning,
    is_trial,
    open_for_reading,
    trials_in,
    warn_unchecked_once,
)


@dataclass(frozen=True)
class BatchResults:
    """Every table of a batch, one row per trial / test / word / curve point, each row labelled
    with its trial (`trial`, the directory name), `group` (grasp, plus babbling when a batch
    mixes modes) and `seed`.

    - trials: eval.json's numbers (competence_all, competence_ring1..3, share_below_threshold,
      median_names, median_distractors, ...), diverged iterations, timing.json's
      seconds / timed_iterations (NaN when not recorded), and `reach`, how far the hand can
      take the stick (m), and its capabilities (solid, pushes, closed_form: true or false),
      as the trial's backend declared them (backend.json).
    - competence: competence.parquet rows (ring, placement, toy, x, y, distance, strategy,
      error, random_error, ...).
    - vocal: vocal.parquet rows (word, is_name, toy, best_distance); `toy` (the toy a name
      names, 0 for a distractor) is missing in trials evaluated before it was recorded.
    - curves: long table (iteration, metric, value) of developmental curves
      (experiments/analysis/curves.py).
    - configs: group -> the group's common config (trial.seed removed).
    - provenance: where each trial was computed (role 'computed', one row per stretch of
      iterations, from provenance.json) and evaluated (role 'evaluated', from eval.json):
      from_iteration, status ('recorded', 'not recorded', 'unreadable') and
      provenance.SHORT_FIELDS (cpu, simd, blas, numpy, mujoco, host, commit).
    """

    batch_dir: Path
    trials: pd.DataFrame
    competence: pd.DataFrame
    vocal: pd.DataFrame
    curves: pd.DataFrame
    configs: dict[str, dict]
    study_tests: pd.DataFrame = dataclasses.field(
        default_factory=lambda: pd.DataFrame(columns=["group"])
    )
    provenance: pd.DataFrame = dataclasses.field(
        default_factory=lambda: pd.DataFrame(columns=["group", "seed"])
    )

    @property
    def groups(self) -> list[str]:
        return list(self.configs)

    def select(self, group: str) -> BatchResults:
        """The results of one group only."""
        keep = {name: table[table["group"] == group] for name, table in self._tables().items()}
        return dataclasses.replace(self, **keep, configs={group: self.configs[group]})

    def with_seeds(self, seeds: set[int]) -> BatchResults:
        """The results of the trials whose seed is in `seeds` only."""
        keep = {n: t[t["seed"].isin(seeds)] for n, t in self._tables().items() if "seed" in t}
        return dataclasses.replace(self, **keep)

    def relabel(self, mapping: dict[str, str]) -> BatchResults:
        """The same results with groups renamed (to tell two batches apart)."""
        tables = {}
        for name, table in self._tables().items():
            table = table.copy()
            table["group"] = table["group"].map(lambda g: mapping.get(g, g))
            tables[name] = table
        configs = {mapping.get(g, g): c for g, c in self.configs.items()}
        return dataclasses.replace(self, **tables, configs=configs)

    def merge(self, other: BatchResults) -> BatchResults:
        """Both batches' tables in one (their groups must differ); batch_dir is this one's."""
        tables = {
            name: pd.concat([table, other._tables()[name]], ignore_index=True)
            for name, table in self._tables().items()
        }
        return dataclasses.replace(self, **tables, configs={**self.configs, **other.configs})

    # The table fields by name, typed Any: they go back to dataclasses.replace as keywords,
    # which mypy checks against every field's type.
    def _tables(self) -> dict[str, Any]:
        return {
            "trials": self.trials,
            "competence": self.competence,
            "vocal": self.vocal,
            "curves": self.curves,
            "study_tests": self.study_tests,
            "provenance": self.provenance,
        }


def _read_json(path: Path) -> Any:
    try:
        return storage.read_json(path)
    except storage.CorruptFileError as exc:
        raise ReportError(str(exc)) from None


def read_summary(trial_dir: Path, config: dict, folder: Path | None = None) -> dict:
    """The eval.json of a trial's evaluation in `folder` (default: its own, in the trial
    directory), checked against itself and the trial's `config`
    (experiments/trial_dir/eval_record.py); ReportError (one line naming the file and what to do)
    otherwise."""
    try:
        return open_for_reading(trial_dir).evaluation(folder).summary(config)
    except storage.CorruptFileError as exc:
        raise ReportError(" ".join(str(exc).split())) from None


def _names(paths: list[Path], limit: int = 5) -> str:
    shown = ", ".join(p.name for p in paths[:limit])
    return shown + (f" and {len(paths) - limit} more" if len(paths) > limit else "")


def _trial_dirs(batch_dir: Path, eval_dir: Callable[[Path], Path]) -> list[Path]:
    if not batch_dir.is_dir():
        raise ReportError(f"{batch_dir} is not a directory")
    if is_trial(batch_dir):
        raise ReportError(
            f"{batch_dir} is a trial directory, not a batch: give the folder that holds trial "
            f"directories (this one is in {batch_dir.resolve().parent})"
        )
    dirs = trials_in(batch_dir)
    if not dirs:
        raise ReportError(
            f"no trial directories found in {batch_dir}: a batch directory holds one folder per "
            f"trial (its {TRIAL_MARKS}), as `playroom batch --out DIR` writes them"
        )
    evaluations = [open_for_reading(d).evaluation(eval_dir(d)) for d in dirs]
    missing = [d for d, e in zip(dirs, evaluations, strict=True) if not e.exists()]
    if missing:
        raise ReportError(
            f"{len(missing)} of {len(dirs)} trials in {batch_dir} have no "
            f"{evaluations[0].path.name} (not evaluated): {_names(missing)}; run `playroom eval` "
            "on them"
        )
    return dirs


def check_out_dir(out_dir: Path) -> None:
    """ReportError, before any work, if out_dir cannot be written (a read-only place, a file)."""
    try:
        storage.check_writable(out_dir)
    except OSError as exc:
        raise ReportError(f"cannot write into {out_dir}: {storage.reason(exc)}") from None


def _check_evaluations(label: str, trials: list[tuple[Path, dict, dict]]) -> None:
    """Every trial of group `label` (directory, config, eval.json) was evaluated at its end on
    the same number of placements (its settings were checked before: `check_group`)."""
    for d, config, summary in trials:
        if summary.get("evaluated_at_iteration") != config["trial"]["iterations"]:
            raise ReportError(
                f"{d.name} was evaluated at iteration {summary.get('evaluated_at_iteration')} "
                f"of {config['trial']['iterations']}: finish the trial and evaluate it again"
            )
    placements = {summary.get("n_placements") for _, _, summary in trials}
    if len(placements) > 1:
        raise ReportError(
            f"trials of group {label} were evaluated on different numbers of placements "
            f"({sorted(placements, key=str)}): evaluate them again with the same --placements"
        )
    clear = {bool(summary.get(SCENES_KEY, False)) for _, _, summary in trials}
    if len(clear) > 1:
        raise ReportError(
            f"trials of group {label} were evaluated on different scenes, some with "
            "--scenes-clear-of-stick and some without: evaluate them again alike"
        )


def collect(batch_dir: str | os.PathLike, eval_dir: Callable[[Path], Path] = Path) -> BatchResults:
    """Read every trial of a batch directory into tables. ReportError (one line) for a
    directory without trials, trials not evaluated, or mismatched configs within a group.
    `eval_dir`: the folder of a trial's evaluation read (default: the trial directory; another
    world's: experiments/analysis/eval_world_results.py)."""
    batch_dir = Path(batch_dir)
    dirs = _trial_dirs(batch_dir, eval_dir)
    try:  # trials of another batch than batch.json records: never drawn under its name
        check_trials_agree(batch_dir, dirs)
    except RecordMismatch as exc:
        raise ReportError(str(exc)) from None
    trials = [open_for_reading(d) for d in dirs]
    configs = [_read_json(t.config_path) for t in trials]
    configs = [with_added_settings(c) if isinstance(c, dict) else c for c in configs]
    for trial, config in zip(trials, configs, strict=True):
        if not isinstance(config, dict) or not {"grasp", "babbling", "seed", "iterations"} <= set(
            config.get("trial", {})
        ):
            raise ReportError(f"{trial.config_path} lacks the trial's grasp/babbling/seed")
    # Babbling joins the label only when it tells groups apart, to keep labels short.
    mixed = len({c["trial"]["babbling"] for c in configs}) > 1
    labels = [group_label(c["trial"]["grasp"], c["trial"]["babbling"], mixed) for c in configs]
    groups = {lab: [i for i, x in enumerate(labels) if x == lab] for lab in sorted(set(labels))}
    for label, members in groups.items():  # the settings first: what differs is named
        try:  # every setting but the seed agrees; seeds are distinct
            check_group(label, [dirs[i] for i in members], [configs[i] for i in members])
        except BatchMismatch as exc:
            raise ReportError(str(exc)) from None
    group_configs: dict[str, dict] = {}
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", UncheckedTrialWarning)
        evals = [read_summary(d, c, eval_dir(d)) for d, c in zip(dirs, configs, strict=True)]
        for label, members in groups.items():
            _check_evaluations(label, [(dirs[i], configs[i], evals[i]) for i in members])
            group_configs[label] = shared_config(configs[members[0]])
        rows = [
            trial_rows(d, config, summary, label, eval_dir(d))
            for d, config, summary, label in zip(dirs, configs, evals, labels, strict=True)
        ]
    warn_unchecked_once(batch_dir, dirs, caught)
    trials, competence, vocal, curves, study = zip(*rows, strict=True)
    where = [
        row
        for d, summary, row_keys in zip(dirs, evals, trials, strict=True)
        for row in provenance_rows(d, summary, {k: row_keys[k] for k in ("trial", "group", "seed")})
    ]
    studied = [t for t in study if t is not None]
    return BatchResults(
        batch_dir=batch_dir,
        trials=pd.DataFrame(list(trials)),
        competence=pd.concat(competence, ignore_index=True),
        vocal=pd.concat(vocal, ignore_index=True),
        curves=pd.concat(curves, ignore_index=True),
        configs=group_configs,
        study_tests=(
            pd.concat(studied, ignore_index=True) if studied else pd.DataFrame(columns=["group"])
        ),
        provenance=pd.DataFrame(where),
    )
