"""The vocal tract as a trial setting: chosen once, recorded, refused on a resume that changes
it, in batches and their profiles; DIVA without its data stops in one line; trials written
before the setting existed resume as they are."""

from __future__ import annotations

import dataclasses
import json

import pytest

from experiments.batches.spec import BatchError, BatchSpec, load_spec
from experiments.cli.main import main
from experiments.run.settings import TrialSettings, resume_settings
from experiments.run.trial import run_trial
from experiments.run.trial_config import full_config
from experiments.trial_dir import storage
from experiments.trial_dir.config_file import trial_identity
from experiments.trial_dir.errors import TrialError
from experiments.trial_dir.layout import CONFIG_FILE, PROVENANCE_FILE
from sim.vocal.diva import data


def test_diva_without_its_data_stops_in_one_line_and_writes_nothing(tmp_path, monkeypatch, capsys):
    monkeypatch.setenv(data.DATA_ENV, str(tmp_path / "no-data"))
    out = tmp_path / "t"
    with pytest.raises(TrialError, match="needs DIVA's map, which is not installed"):
        run_trial(out, TrialSettings(iterations=5, voice="diva"), progress=False)
    assert not out.exists()
    code = main(["run", "--out", str(out), "--iterations", "5", "--voice", "diva"])
    err = capsys.readouterr().err.strip()
    assert code == 2 and "\n" not in err and "playroom voice-data diva PATH" in err
    assert not out.exists() and not (tmp_path / "no-data").exists()


def test_a_diva_trial_records_its_voice_and_refuses_another_on_resume(
    tmp_path, installed_generated_map, capsys
):
    out = tmp_path / "t"
    trial = run_trial(out, TrialSettings(iterations=30, voice="diva"), progress=False)
    assert type(trial.room.vocal_tract).__name__ == "DivaTract"
    config = storage.read_json(out / CONFIG_FILE)
    assert config["trial"]["voice"] == config["world"]["voice"] == "diva"
    record = storage.read_json(out / PROVENANCE_FILE)[0]["record"]
    assert record["inputs"] == {"diva_map": data.map_digest(installed_generated_map)}
    assert resume_settings(out, {}).voice == "diva"
    with pytest.raises(TrialError, match=r"--voice vtl \(it has diva\)"):
        resume_settings(out, {"voice": "vtl"})
    assert main(["run", "--out", str(out), "--resume", "--voice", "vtl"]) == 2
    assert "--voice vtl (it has diva)" in capsys.readouterr().err
    with pytest.raises(TrialError, match="overrides.world.voice is the trial setting voice"):
        TrialSettings(overrides={"world": {"voice": "diva"}})


def test_a_trial_written_before_the_voice_setting_resumes_as_it_is(tmp_path):
    out = tmp_path / "t"
    settings = TrialSettings(iterations=20, checkpoint_every=10)
    run_trial(out, settings, progress=False)
    config = storage.read_json(out / CONFIG_FILE)
    identity = trial_identity(config)
    del config["trial"]["voice"], config["world"]["voice"]  # as older trials wrote it
    storage.write_json(out / CONFIG_FILE, config)
    assert trial_identity(config) == identity  # its checkpoints stay its own
    assert resume_settings(out, {}) == settings
    trial = run_trial(
        out, dataclasses.replace(settings, iterations=30), resume=True, progress=False
    )
    assert trial.iteration == 30 and trial.room.vocal_tract.name == "vtl"


def test_batches_and_profiles_choose_the_voice(tmp_path, monkeypatch, installed_generated_map):
    spec = load_spec(profile="replication-diva")
    assert spec.voice == "diva" and all(s.voice == "diva" for _, s in spec.trials()[:3])
    assert BatchSpec().voice == "vtl"
    with pytest.raises(BatchError, match="voice must be one of vtl, diva"):
        BatchSpec(voice="DIVA")
    path = tmp_path / "b.json"
    path.write_text(json.dumps({"seeds": 1, "iterations": 5, "voice": "diva"}))
    monkeypatch.setenv(data.DATA_ENV, str(tmp_path / "no-data"))
    with pytest.raises(BatchError, match="needs DIVA's map"):
        load_spec(config_file=path)  # checked before anything starts


def test_full_config_names_the_tract_in_the_world(installed_generated_map):
    config = full_config(TrialSettings(voice="diva"))
    assert config["world"]["voice"] == "diva"
    assert full_config(TrialSettings())["world"]["voice"] == "vtl"
