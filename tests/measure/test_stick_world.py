"""The row "random arm commands that grasp the stick at its start" plays each backend in the
world its trials ran in: the DMP of the trials' preset turns the commands into
movements, and the project's DMP grasps another share of the same commands than the study's."""

from __future__ import annotations

import argparse
import dataclasses

from experiments.cli.report_commands import study_reference
from experiments.measure.stick import batch_worlds, grasp_rates
from experiments.run.settings import TrialSettings
from experiments.run.trial_config import full_config
from experiments.trial_dir.storage import write_json
from sim.config import world_preset

COMMANDS = 200


def _batch(root, preset: str):
    """A batch directory holding one trial's directory (its config.json and log/), as far as
    choosing a world reads it."""
    trial = root / preset / "kinematic-random-seed0000"
    (trial / "log").mkdir(parents=True)
    write_json(trial / "config.json", full_config(TrialSettings(grasp="kinematic", preset=preset)))
    return root / preset


def test_the_grasp_rates_of_a_report_play_the_trials_own_world(tmp_path):
    args = argparse.Namespace(study_reference_commands=None, workers=1)
    rates = {}
    for preset in ("study", "project"):
        measures = study_reference(args, [str(_batch(tmp_path, preset))])["measures"]
        rates[preset] = measures.grasp_rates(COMMANDS, ("kinematic",))["kinematic"]
        world = {"kinematic": dataclasses.asdict(world_preset(preset))}
        played = grasp_rates(COMMANDS, ("kinematic",), progress=False, worlds=world)
        assert rates[preset] == played["kinematic"], preset
    # The worlds differ in their DMP, and so do the shares: 0.28 against 0.265 here.
    assert rates["study"] != rates["project"]


def test_batch_worlds_take_each_backend_from_the_first_batch_that_ran_it(tmp_path):
    study, project = _batch(tmp_path, "study"), _batch(tmp_path, "project")
    assert batch_worlds([study, project])["kinematic"]["dmp"] == "study"
    assert batch_worlds([project, study])["kinematic"]["dmp"] == "project"
    assert batch_worlds([tmp_path / "none"]) == {}
