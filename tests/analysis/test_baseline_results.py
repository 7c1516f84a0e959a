"""Baseline runs read as a batch's tables (experiments/analysis/baseline_results.py): one row per
run, the tests of each labelled with its run, grasp and seed; a run unfinished or damaged is
refused in one line. The runs here are written by the evaluation a baseline's run writes
(trial_evaluation.measured) of a policy that rests the arm: no RL library needed."""

from __future__ import annotations

import shutil

import pytest
from baseline_runs import write_run
from bit_flips import flip_number

from experiments.analysis.baseline_results import collect_baselines
from experiments.analysis.results import ReportError
from experiments.baseline.settings import BaselineSettings, run_name
from experiments.trial_dir import storage
from experiments.trial_dir.layout import COMPETENCE_FILE, EVAL_FILE


@pytest.fixture
def runs(tmp_path):
    for seed in (0, 3):
        write_run(tmp_path, seed)
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


def test_a_damaged_or_another_runs_eval_json_is_refused_in_one_line(runs):
    first, other = (runs / run_name(BaselineSettings(steps=30, seed=s)) for s in (0, 3))
    path = other / EVAL_FILE
    ring1 = storage.read_json(path)["competence"]["ring1"]
    flip_number(path, "ring1", ring1)  # still JSON, another number
    with pytest.raises(ReportError, match=f"{path} is damaged") as damaged:
        collect_baselines(runs)
    assert "rl-baseline" in str(damaged.value) and "\n" not in str(damaged.value)
    shutil.copyfile(first / EVAL_FILE, path)  # another run's, intact
    with pytest.raises(ReportError, match=f"{path} is the evaluation of another trial"):
        collect_baselines(runs)
