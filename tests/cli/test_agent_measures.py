"""`playroom replay` and `playroom voice-memory`: the experiments on finished trials' final
agents as commands, each writing its CSV and printing its summary per backend; a folder with
no finished trial refused in one line, nothing written."""

from __future__ import annotations

import shutil

import pandas as pd

from experiments.cli.main import main
from experiments.measure.evaluation import EvaluationSettings
from experiments.measure.trial_evaluation import evaluate_trial


def test_replay_writes_a_row_per_test_and_its_figure(trained_trial, tmp_path, capsys):
    batch = tmp_path / "batch"
    trial = batch / "kinematic-random-seed0000"
    shutil.copytree(trained_trial.dir, trial)
    evaluate_trial(trial, EvaluationSettings(n_placements=6))
    out, figure = tmp_path / "replay.csv", tmp_path / "replay.png"
    args = [str(batch), "--trials", "1", "--out", str(out), "--figure", str(figure)]
    assert main(["replay", *args]) == 0
    table = pd.read_csv(out)
    # Ring 1's arm tests of the trial's evaluation (6 placements x 3 toys at most), each in
    # four scenes, beside the random command the evaluation played there.
    assert set(table["trial"]) == {trial.name} and 0 < len(table) <= 18
    assert table["random_error"].notna().all()
    assert {"repeat_alone", "repeat_test", "error_test"} <= set(table.columns)
    printed = capsys.readouterr().out
    assert "medians per backend" in printed and "kinematic" in printed
    assert figure.read_bytes().startswith(b"\x89PNG")


def test_voice_memory_writes_a_row_per_toy_model(trained_trial, tmp_path, capsys):
    out = tmp_path / "memory.csv"
    assert main(["voice-memory", str(trained_trial.dir), "--out", str(out)]) == 0
    table = pd.read_csv(out)
    assert list(table["toy"]) == [1, 2, 3] and set(table["grasp"]) == {"kinematic"}
    assert "trials per backend: {'kinematic': 1}" in capsys.readouterr().out


def test_a_folder_without_finished_trials_is_refused_in_one_line(tmp_path, capsys):
    out = tmp_path / "x.csv"
    assert main(["replay", str(tmp_path), "--out", str(out)]) == 2
    assert main(["voice-memory", str(tmp_path), "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 2 and "holds no finished trial" in err[0] and "holds no trial" in err[1]
    assert not out.exists()
