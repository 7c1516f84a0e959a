"""What `playroom batch` and the readers of a batch refuse before they write anything or compute
a number: a damaged batch record, a trial directory given as a batch's, a batch
that cannot fit on its disk, a config naming a key twice."""

from __future__ import annotations

import dataclasses
import json
import shutil

import pytest

from experiments.batch_files import BATCH_FILE, REPORT_FILE
from experiments.batches.spec import load_spec, spec_record
from experiments.cli.main import main
from experiments.trial_dir import storage
from experiments.trial_dir.layout import CONFIG_FILE


def _cli(capsys, *argv: str) -> tuple[int, list[str]]:
    code = main(list(argv))
    return code, capsys.readouterr().err.strip().splitlines()


def _files(directory) -> dict:
    return {p: p.read_bytes() for p in directory.rglob("*") if p.is_file() and p.name != ".lock"}


def test_d5_a_damaged_batch_record_stops_the_report(batches, tmp_path, capsys):
    batch = tmp_path / "batch"
    shutil.copytree(batches["kinematic"], batch)
    # The record `playroom batch` would have written for these trials.
    spec = dataclasses.replace(
        load_spec("smoke"), grasps=("kinematic",), iterations=300, checkpoint_every=300
    )
    storage.write_json(batch / BATCH_FILE, spec_record(spec))
    record = (batch / BATCH_FILE).read_bytes()
    (batch / BATCH_FILE).write_bytes(record[: len(record) // 2])  # truncated
    code, err = _cli(capsys, "report", str(batch), "--out", str(tmp_path / "rep"))
    assert code == 2 and len(err) == 1 and BATCH_FILE in err[0] and "playroom batch" in err[0]
    assert not (tmp_path / "rep" / REPORT_FILE).exists()
    (batch / BATCH_FILE).write_text("[1, 2]")  # JSON, but no record
    code, err = _cli(capsys, "report", str(batch), "--out", str(tmp_path / "rep"))
    assert code == 2 and len(err) == 1 and "not a batch record" in err[0]


def test_d7_a_trial_directory_is_no_batchs_directory(trained_trial, tmp_path, capsys):
    trial = tmp_path / "trial"
    shutil.copytree(trained_trial.dir, trial)
    before = _files(trial)
    code, err = _cli(capsys, "batch", "--profile", "smoke", "--out", str(trial), "--quiet")
    assert code == 2 and len(err) == 1 and "is a trial directory" in err[0]
    assert _files(trial) == before


def test_d8_a_batch_that_cannot_fit_is_refused_before_anything_is_written(tmp_path, capsys):
    config = tmp_path / "huge.json"
    config.write_text(json.dumps({"base": "smoke", "grasps": ["kinematic"], "iterations": 10**9}))
    out = tmp_path / "huge"
    code, err = _cli(capsys, "batch", "--config", str(config), "--out", str(out), "--quiet")
    assert code == 2 and len(err) == 1 and "free" in err[0] and "need" in err[0]
    assert not out.exists()  # no batch.json blocks the corrected rerun


def test_d9_a_key_given_twice_is_refused_in_a_batch_config(tmp_path, capsys):
    config = tmp_path / "twice.json"
    config.write_text('{"base": "smoke", "seeds": 2, "seeds": 5}')
    code, err = _cli(capsys, "batch", "--config", str(config), "--out", str(tmp_path / "b"))
    assert code == 2 and len(err) == 1 and "'seeds' appears twice" in err[0]
    assert not (tmp_path / "b").exists()


def test_d9_a_key_given_twice_is_refused_in_a_trials_config(trained_trial, tmp_path, capsys):
    trial = tmp_path / "trial"
    shutil.copytree(trained_trial.dir, trial)
    text = (trial / CONFIG_FILE).read_text()
    (trial / CONFIG_FILE).write_text(
        text.replace('"exploration_sigma"', '"exploration_sigma": 0.5, "exploration_sigma"', 1)
    )
    before = _files(trial)
    for argv in (["eval", str(trial), "--quiet"], ["run", "--out", str(trial), "--resume"]):
        code, err = _cli(capsys, *argv)
        assert code == 2 and len(err) == 1 and "'exploration_sigma' appears twice" in err[0]
    assert _files(trial) == before
    with pytest.raises(storage.CorruptFileError, match="appears twice"):
        storage.read_json(trial / CONFIG_FILE)


def test_d10_an_unknown_setting_in_a_trials_config_is_named_as_such(
    trained_trial, tmp_path, capsys
):
    from experiments.analysis.logs import read_log

    trial = tmp_path / "trial"
    shutil.copytree(trained_trial.dir, trial)
    config = storage.read_json(trial / CONFIG_FILE)
    config["world"]["foo"] = 1
    storage.write_json(trial / CONFIG_FILE, config)
    before = _files(trial)
    for argv in (["eval", str(trial), "--quiet"], ["run", "--out", str(trial), "--resume"]):
        code, err = _cli(capsys, *argv)
        assert code == 2 and len(err) == 1, err
        assert "unknown setting world.foo" in err[0] and "another" not in err[0]
    with pytest.raises(storage.CorruptFileError, match="unknown setting world.foo"):
        read_log(trial)  # not "belongs to another trial"
    assert _files(trial) == before
