"""Deep-RL baseline runs (`playroom rl-baseline`, experiments/baseline/) read into the tables a
batch of trials is read into (results.py): one row per run in `trials` (eval.json's numbers:
competence_all, competence_ring1..3, mean errors, vocal numbers), the rows of its
competence.parquet, vocal.parquet and study-tests.parquet, each labelled with its run
(`trial`, the directory name), `group` (the grasp) and `seed`, every table checked against
eval.json's list of files. A run has no logs: no curves, no mechanisms. The tables have a
trial's columns, so that the statistics over trials (trial_values.py, trial_tests.py) pair a
baseline's runs with Model Babbling's trials by seed."""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path

import pandas as pd

from experiments.analysis.batch_checks import shared_config
from experiments.analysis.results import BatchResults, ReportError, _read_json
from experiments.analysis.trial_rows import eval_numbers, evaluation_table
from experiments.trial_dir import storage
from experiments.trial_dir.baseline_run import BASELINE_RUN_MARK, open_baseline_run
from experiments.trial_dir.evaluation import TABLES
from experiments.trial_dir.provenance import SHORT_FIELDS, short_record


@dataclass(frozen=True)
class BaselineResults:
    """Every table of a folder of baseline runs (the module's docstring)."""

    runs_dir: Path
    trials: pd.DataFrame
    competence: pd.DataFrame
    vocal: pd.DataFrame
    study_tests: pd.DataFrame
    configs: dict[str, dict]  # grasp -> the trials' world the runs learned in (seed removed)
    # Where each run was computed (baseline.json's `created_on`): role 'computed',
    # provenance.SHORT_FIELDS, as BatchResults.provenance holds a trial's.
    provenance: pd.DataFrame

    def as_batch(self) -> BatchResults:
        """The runs as a batch's results (no curves: a run has no logs), so that every
        per-trial measure of the registry (experiments/report/measures.py) reads them."""
        return BatchResults(
            batch_dir=self.runs_dir,
            trials=self.trials,
            competence=self.competence,
            vocal=self.vocal,
            curves=pd.DataFrame(columns=["trial", "group", "seed", "iteration", "metric", "value"]),
            configs=self.configs,
            study_tests=self.study_tests,
            provenance=self.provenance,
        )


def _summary(run_dir: Path, config: dict) -> dict:
    """A run's eval.json, checked against itself and the trial config its baseline.json
    records (experiments/trial_dir/eval_record.py); ReportError (one line) otherwise."""
    remedy = (
        f"remove it and run the same `playroom rl-baseline` command into {run_dir} again "
        "(its trained policies are kept)"
    )
    try:
        return open_baseline_run(run_dir).evaluation().summary(config, remedy)
    except storage.CorruptFileError as exc:
        raise ReportError(" ".join(str(exc).split())) from None


def collect_baselines(runs_dir: str | os.PathLike) -> BaselineResults:
    """Read every run of a folder (`playroom rl-baseline --config ... --out DIR`'s DIR) into
    tables. ReportError (one line) for a folder without runs, a run not evaluated, or a table
    missing or damaged."""
    root = Path(runs_dir)
    if not root.is_dir():
        raise ReportError(f"{root} is not a directory")
    runs = [open_baseline_run(d) for d in sorted(root.iterdir()) if d.is_dir()]
    runs = [run for run in runs if run.is_run()]
    if not runs:
        raise ReportError(f"no baseline runs found in {root} (folders holding {BASELINE_RUN_MARK})")
    dirs = [run.dir for run in runs]
    unfinished = [run.dir.name for run in runs if not run.evaluation().path.is_file()]
    if unfinished:
        name = runs[0].evaluation().path.name
        raise ReportError(
            f"{len(unfinished)} of {len(dirs)} runs in {root} are not finished (no {name}): "
            f"{', '.join(unfinished[:5])}; run the same `playroom rl-baseline` command again"
        )
    trials: list[dict] = []
    tables: dict[str, list[pd.DataFrame]] = {kind: [] for kind in TABLES}
    configs: dict[str, dict] = {}
    where = []
    for run in runs:
        d = run.dir
        recorded = _read_json(run.record_path)
        config = recorded.get("trial") if isinstance(recorded, dict) else None
        if not isinstance(config, dict) or not isinstance(config.get("trial"), dict):
            raise ReportError(f"{run.record_path} lacks the trial's config: run it again")
        summary = _summary(d, config)
        keys = {"trial": d.name, "group": summary["grasp"], "seed": summary["seed"]}
        if configs.setdefault(summary["grasp"], shared_config(config)) != shared_config(config):
            raise ReportError(
                f"{d.name}: its world differs from the other {summary['grasp']} runs' in {root}"
            )
        created = short_record(recorded.get("created_on"))
        status = "not recorded" if created is None else "recorded"
        fields = created or dict.fromkeys(SHORT_FIELDS, "")
        where.append({**keys, "role": "computed", "from_iteration": 0, "status": status, **fields})
        trials.append(
            {
                **keys,
                "path": str(d),
                "grasp": summary["grasp"],
                "babbling": summary.get("babbling"),
                "iterations": summary.get("iterations"),
                "n_placements": summary.get("n_placements"),
                **eval_numbers(run.evaluation().path, summary),
            }
        )
        for kind, rows in tables.items():
            rows.append(evaluation_table(run.evaluation(), kind, summary).assign(**keys))
    return BaselineResults(
        runs_dir=root,
        trials=pd.DataFrame(trials),
        competence=pd.concat(tables["competence"], ignore_index=True),
        vocal=pd.concat(tables["vocal"], ignore_index=True),
        study_tests=pd.concat(tables["study_tests"], ignore_index=True),
        configs=configs,
        provenance=pd.DataFrame(where),
    )
