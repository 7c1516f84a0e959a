"""Long jobs show progress: the study's random reference and the grasp rates draw a bar (on a
terminal by default; asked for here), and reports play the reference at the size the batch's
profile recorded, unless the command line asks for another."""

from __future__ import annotations

import argparse

from experiments.batch_files import BATCH_FILE
from experiments.cli.report_commands import study_reference
from experiments.measure.stick import grasp_rates
from experiments.measure.study_measure import StudyMeasureSettings, random_reference
from experiments.run.settings import TrialSettings
from experiments.run.trial_config import full_config
from experiments.trial_dir import storage


def test_the_random_reference_draws_a_bar_of_its_commands(capsys):
    config = full_config(TrialSettings(grasp="kinematic", seed=0))
    reference = random_reference(
        {"kin": config}, StudyMeasureSettings(random_commands_per_ring=2), progress=True
    )["kin"]
    assert len(reference) == 6  # 3 rings x 2 commands
    err = capsys.readouterr().err
    assert "study reference kin" in err and "6/6" in err


def test_no_bar_unless_asked_or_on_a_terminal(capsys):
    config = full_config(TrialSettings(grasp="kinematic", seed=0))
    random_reference({"kin": config}, StudyMeasureSettings(random_commands_per_ring=1))
    assert capsys.readouterr().err == ""  # pytest's stderr is no terminal


def test_the_grasp_rates_draw_a_bar(capsys):
    rates = grasp_rates(n_commands=2, progress=True)
    assert set(rates) == {"kinematic", "physical"}
    err = capsys.readouterr().err
    assert "grasp rates" in err and "4/4" in err


def test_reports_play_the_reference_the_batch_recorded_unless_asked_otherwise(tmp_path):
    storage.write_json(tmp_path / BATCH_FILE, {"study_reference_commands": 300})

    def size(given: int | None, dirs: list) -> int:
        args = argparse.Namespace(study_reference_commands=given)
        return study_reference(args, dirs)["measures"].study_numbers.keywords["commands_per_ring"]

    assert size(None, [tmp_path]) == 300
    assert size(10, [tmp_path]) == 10
    assert size(None, [tmp_path / "no-record"]) == 30000
