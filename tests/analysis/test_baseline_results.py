"""Baseline runs read as a batch's tables (experiments/analysis/baseline_results.py): one row per
run, the tests of each labelled with its run, grasp and seed; a run unfinished or damaged is
refused in one line. The runs here are written by the evaluation a baseline's run writes
(trial_evaluation.measured) of a policy that rests the arm: no RL library needed."""

from __future__ import annotations

import numpy as np
import pytest

from experiments import storage
from experiments.analysis.baseline_results import collect_baselines
from experiments.analysis.results import ReportError
from experiments.baseline.settings import BaselineSettings, run_name, summary_config, trial_config
from experiments.file_names import BASELINE_FILE, COMPETENCE_FILE, EVAL_FILE
from experiments.measure.evaluation import EvaluationSettings
from experiments.measure.policy_actor import PolicyActor
from experiments.measure.trial_evaluation import evaluation_files, measured
from experiments.run.trial_files import fresh_trial_parts


class RestingPolicy:
    def predict(self, observation, deterministic=False):
        action = np.zeros(50, dtype=np.float32)
        action[0] = -1.0  # the arm, at rest
        return action, None


def _write_run(root, seed: int) -> None:
    settings = BaselineSettings(steps=30, seed=seed, eval_placements=1)
    _, room = fresh_trial_parts(trial_config(settings))
    actor = PolicyActor({t: RestingPolicy() for t in (1, 2, 3)})
    summary, tables = measured(
        actor, actor, room, EvaluationSettings(1), summary_config(settings), np.full(6, np.inf), 30
    )
    out = root / run_name(settings)
    record = storage.json_bytes({"settings": settings.record()})
    storage.write_files(out, {BASELINE_FILE: record, **evaluation_files(summary, tables)})


@pytest.fixture
def runs(tmp_path):
    for seed in (0, 3):
        _write_run(tmp_path, seed)
    return tmp_path


def test_runs_are_read_as_a_batchs_tables(runs):
    results = collect_baselines(runs)
    assert list(results.trials["seed"]) == [0, 3]
    assert set(results.trials["babbling"]) == {"sac-her"} and set(results.trials["group"]) == {
        "kinematic"
    }
    assert {"competence_all", "competence_ring1", "mean_random_error"} <= set(results.trials)
    # A row per test of each run, labelled with it: 3 rings x 1 placement x 3 toys.
    assert results.competence.groupby("seed").size().to_dict() == {0: 9, 3: 9}
    assert len(results.study_tests) == 18 and len(results.vocal) == 12
    # The numbers of eval.json are those of its tables.
    run = results.competence[results.competence["seed"] == 3]
    expected = 1 - run["error"].mean() / run["random_error"].mean()
    got = results.trials.set_index("seed").loc[3, "competence_all"]
    assert got == pytest.approx(expected)


def test_an_unfinished_or_damaged_run_is_refused_in_one_line(runs, tmp_path):
    name = run_name(BaselineSettings(steps=30, seed=3))
    table = runs / name / COMPETENCE_FILE
    table.write_bytes(table.read_bytes()[:-10])
    with pytest.raises(ReportError, match=COMPETENCE_FILE) as damaged:
        collect_baselines(runs)
    (runs / name / EVAL_FILE).unlink()
    with pytest.raises(ReportError, match="1 of 2 runs .* are not finished") as unfinished:
        collect_baselines(runs)
    with pytest.raises(ReportError, match="no baseline runs found"):
        collect_baselines(runs / name)  # a run, not a folder of runs
    for caught in (damaged, unfinished):
        assert "\n" not in str(caught.value)
