"""A trial's final agent tested in another world (issue 40): written beside the trial, never over
its files, saying which world tested it; read back by the cross-world table, own evaluation
where the trial learned in that world; checked like the own evaluation."""

from __future__ import annotations

import dataclasses
import shutil

import pytest

from experiments import storage
from experiments.analysis.cross_worlds import MissingTestError, cross_table
from experiments.cli.main import main
from experiments.config_file import config_tested_in
from experiments.file_names import (
    CONFIG_FILE,
    EVAL_FILE,
    EVALUATION_TABLES,
    LOCK_FILE,
    STUDY_TESTS_FILE,
    cross_evaluation_dir,
)
from experiments.measure.cross_evaluation import evaluate_in_world
from experiments.measure.evaluation import EvaluationSettings
from experiments.measure.trial_evaluation import evaluate_trial
from experiments.run.settings import TrialSettings
from experiments.run.trial import run_trial
from sim.config import ACTS_ON, WorldConfig

ONE = EvaluationSettings(n_placements=1)


def _files(directory) -> dict:
    return {p: p.read_bytes() for p in directory.rglob("*") if p.is_file() and p.name != LOCK_FILE}


@pytest.fixture
def batch(trained_trial, tmp_path):
    """A one-trial batch: the session's kinematic trial (study preset), evaluated."""
    trial = tmp_path / "batch" / "kinematic-random-seed0000"
    shutil.copytree(trained_trial.dir, trial)
    evaluate_trial(trial, ONE)
    return trial.parent


def test_the_physical_world_tests_the_agent_beside_its_files(batch):
    trial = batch / "kinematic-random-seed0000"
    before = _files(trial)
    summary = evaluate_in_world(trial, "physical", ONE)
    assert _files(trial) == {**before, **_files(cross_evaluation_dir(trial, "physical"))}
    written = storage.read_json(cross_evaluation_dir(trial, "physical") / EVAL_FILE)
    assert written["test_world"]["name"] == "physical" == summary["test_world"]["grasp"]
    assert written["grasp"] == "kinematic"  # the agent's own backend, as it learned
    assert set(written["files"]) == set(EVALUATION_TABLES)
    # The study preset's kinematic trial is tested by the preset's physical rules.
    config = storage.read_json(trial / CONFIG_FILE)
    tested = config_tested_in(config, "physical")
    assert tested["world"]["push_objects"] is True and tested["trial"]["grasp"] == "physical"
    switches = {f.name for f in dataclasses.fields(WorldConfig) if ACTS_ON in f.metadata}
    changed = {k for k, v in tested["world"].items() if v != config["world"][k]}
    assert changed <= switches  # only the backends' own rules change; the rest is the trial's
    table = cross_table({"k0": batch}, ("kinematic", "physical"))
    assert table.set_index("world")["evaluation"].to_dict() == {
        "kinematic": "own",
        "physical": "cross",
    }
    assert table["competence_all"].between(-5, 1).all()


def test_the_own_world_is_refused_in_one_line(batch, capsys):
    trial = batch / "kinematic-random-seed0000"
    before = _files(trial)
    code = main(["eval", str(trial), "--world", "kinematic", "--placements", "1", "--quiet"])
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2 and len(err) == 1 and "learned in the kinematic world itself" in err[0]
    assert _files(trial) == before


def test_a_missing_or_damaged_cross_evaluation_is_refused_by_the_reader(batch):
    trial = batch / "kinematic-random-seed0000"
    with pytest.raises(MissingTestError, match="--world physical"):
        cross_table({"k0": batch}, ("physical",))
    evaluate_in_world(trial, "physical", ONE)
    table = cross_evaluation_dir(trial, "physical") / STUDY_TESTS_FILE
    storage.write_table(table, storage.read_table(table).iloc[:-1])
    with pytest.raises(storage.CorruptFileError, match=STUDY_TESTS_FILE):
        cross_table({"k0": batch}, ("physical",))


def test_an_extended_trial_moves_its_cross_evaluations_aside(batch):
    trial = batch / "kinematic-random-seed0000"
    evaluate_in_world(trial, "physical", ONE)
    config = storage.read_json(trial / CONFIG_FILE)["trial"]
    settings = TrialSettings(
        iterations=config["iterations"] + 100, seed=0, checkpoint_every=config["checkpoint_every"]
    )
    run_trial(trial, dataclasses.replace(settings), resume=True, progress=False)
    stale = trial / f"stale-at-{config['iterations']:08d}"
    assert (stale / "eval-in-physical" / EVAL_FILE).exists()
    assert not cross_evaluation_dir(trial, "physical").exists()
