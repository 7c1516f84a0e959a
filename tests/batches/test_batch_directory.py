"""A batch directory holds one batch: a rerun with other settings is refused in one
line before anything is written or any cluster started, trials that disagree with the batch
are named, reports refuse a directory whose trials disagree with its record, and a batch's
logs read while it runs leave its unfinished trials out, saying which."""

from __future__ import annotations

import dataclasses
import json
import logging
import shutil
from pathlib import Path

import pytest

from experiments.analysis.finished import IncompleteTrialsWarning
from experiments.analysis.logs import read_batch_logs
from experiments.analysis.results import ReportError, collect
from experiments.batch_files import BATCH_FILE
from experiments.batches import scheduler as dask_scheduler
from experiments.batches.directory import check_directory
from experiments.batches.runner import run_batch
from experiments.batches.spec import BatchError, load_spec
from experiments.cli.main import main
from experiments.trial_dir import storage
from experiments.trial_dir.layout import CONFIG_FILE

CONFIG = {
    "grasps": ["kinematic"],
    "seeds": 2,
    "iterations": 20,
    "checkpoint_every": 20,
    "eval_placements": 1,
    "study_reference_commands": 30,
    "preset": "study",
}
FIRST, SECOND = "kinematic-random-seed0000", "kinematic-random-seed0001"


@pytest.fixture(scope="module")
def made(tmp_path_factory) -> tuple[Path, Path]:
    """(batch directory, its config file): CONFIG run on an in-process cluster."""
    from distributed import Client, LocalCluster

    root = tmp_path_factory.mktemp("made")
    config = root / "a.json"
    config.write_text(json.dumps(CONFIG))
    logging.getLogger("distributed").setLevel(logging.WARNING)
    with (
        LocalCluster(
            n_workers=1, threads_per_worker=1, processes=False, dashboard_address=None
        ) as cluster,
        Client(cluster) as client,
    ):
        run_batch(load_spec(config_file=config), root / "b", client=client, progress=False)
    return root / "b", config


def _copy(made: tuple[Path, Path], tmp_path: Path) -> Path:
    batch = tmp_path / "b"
    shutil.copytree(made[0], batch)
    return batch


def _files(directory: Path) -> dict[str, tuple[int, int]]:
    """Every file under `directory` with its size and modification time."""
    return {
        str(p.relative_to(directory)): (p.stat().st_size, p.stat().st_mtime_ns)
        for p in sorted(directory.rglob("*"))
        if p.is_file()
    }


def _no_cluster(*args, **kwargs):
    raise AssertionError("a cluster was started for a batch that should have been refused")


@pytest.mark.parametrize(
    "change, sets, said",
    [
        ({"preset": "project"}, [], "made with preset=study, this run asks preset=project"),
        ({}, ["world.grasp_distance=0.2"], 'overrides={}, this run asks overrides={"world"'),
        ({"iterations": 40}, [], "iterations=20, this run asks iterations=40"),
        ({"iterations": 10}, [], "iterations=20, this run asks iterations=10"),
        ({"seeds": [0]}, [], "seeds=[0, 1], this run asks seeds=[0] (seeds may be added, not"),
        ({"grasps": ["physical"]}, [], 'grasps=["kinematic"], this run asks grasps=["physical"]'),
        ({"babbling": ["active"]}, [], 'babbling=["random"], this run asks babbling=["active"]'),
        ({"eval_placements": 2}, [], "eval_placements=1, this run asks eval_placements=2"),
        ({"study_reference_commands": 300}, [], "study_reference_commands=30, this run asks"),
        ({"stick_return": "never"}, [], "stick_return=out_of_reach, this run asks stick_return"),
        ({"checkpoint_every": 10}, [], "checkpoint_every=20, this run asks checkpoint_every=10"),
    ],
)
def test_a_rerun_with_other_settings_is_refused_before_anything_is_written(
    made, tmp_path, capsys, monkeypatch, change, sets, said
):
    batch = made[0]
    before = _files(batch)
    monkeypatch.setattr(dask_scheduler, "connect", _no_cluster)
    config = tmp_path / "other.json"
    config.write_text(json.dumps({**CONFIG, **change}))
    args = ["batch", "--config", str(config), "--out", str(batch)]
    assert main([*args, *(a for s in sets for a in ("--set", s))]) == 2
    err = capsys.readouterr().err
    assert len(err.strip().splitlines()) == 1, err
    assert said in err, err
    assert f"batch {batch} was made with" in err and "use another --out" in err
    assert _files(batch) == before  # batch.json and every trial as they were


def test_the_same_batch_again_or_with_seeds_added_is_the_same_batch(made, capsys):
    batch, config = made
    spec = load_spec(config_file=config)
    check_directory(spec, batch)
    check_directory(dataclasses.replace(spec, seeds=(2, 1, 0), description="more"), batch)
    assert main(["batch", "--config", str(config), "--out", str(batch)]) == 0
    assert "all 2 trials already complete" in capsys.readouterr().out


def test_trials_that_the_batch_would_not_run_are_named_without_a_record(made, tmp_path):
    batch = _copy(made, tmp_path)
    (batch / BATCH_FILE).unlink()  # a batch from before batch.json, or its record lost
    spec = load_spec(config_file=made[1])
    check_directory(spec, batch)  # its trials are this batch's
    other = dataclasses.replace(spec, preset="project")
    with pytest.raises(BatchError) as caught:
        check_directory(other, batch)
    message = str(caught.value)
    assert f"{FIRST} was run with trial.preset=study, this batch runs project" in message
    assert f"2 trials disagree: {FIRST}, {SECOND}" in message and "\n" not in message
    with pytest.raises(BatchError, match=f"holds trials this batch does not run: {SECOND}"):
        check_directory(dataclasses.replace(spec, seeds=(0,)), batch)
    with pytest.raises(BatchError, match="evaluated with eval_placements=1, this batch uses 2"):
        check_directory(dataclasses.replace(spec, eval_placements=2), batch)


def test_f3_a_lost_record_is_refused_by_reports_and_written_again_by_the_same_batch(
    made, tmp_path, capsys, monkeypatch
):
    batch = _copy(made, tmp_path)
    record = (batch / BATCH_FILE).read_bytes()
    (batch / BATCH_FILE).unlink()  # its trials record manifests: a batch of this version's
    page = tmp_path / "page"
    assert main(["report", str(batch), "--out", str(page)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and f"{batch} has no {BATCH_FILE}" in err[0], err
    assert "rerun `playroom batch` into it with the profile or config" in err[0]
    assert not page.exists()  # not reported at the study's reference size instead
    # What the line says to do: the same batch again writes the record and runs nothing.
    trials = _files(batch)
    monkeypatch.setattr(dask_scheduler, "connect", _no_cluster)
    assert main(["batch", "--config", str(made[1]), "--out", str(batch)]) == 0
    assert "all 2 trials already complete" in capsys.readouterr().out
    assert (batch / BATCH_FILE).read_bytes() == record
    assert {k: v for k, v in _files(batch).items() if k != BATCH_FILE} == trials


def test_an_unreadable_record_is_refused_not_overwritten(made, tmp_path):
    batch = _copy(made, tmp_path)
    (batch / BATCH_FILE).write_text("{")
    with pytest.raises(BatchError, match=r"cannot read .*batch\.json, which says what batch"):
        run_batch(load_spec(config_file=made[1]), batch, progress=False)
    assert (batch / BATCH_FILE).read_text() == "{"


def test_reports_refuse_trials_that_disagree_with_the_record(made, tmp_path, capsys):
    batch = _copy(made, tmp_path)
    # What a rerun with the project preset wrote before it was refused: its record only.
    record = storage.read_json(batch / BATCH_FILE)
    storage.write_json(batch / BATCH_FILE, {**record, "preset": "project"})
    with pytest.raises(ReportError) as caught:
        collect(batch)
    message = str(caught.value)
    assert f"{FIRST} in {batch} ran with preset=study where the record says project" in message
    assert "(and 1 more trial(s))" in message and "\n" not in message
    assert main(["report", str(batch), "--out", str(tmp_path / "page")]) == 2
    err = capsys.readouterr().err
    assert len(err.strip().splitlines()) == 1 and "where the record says project" in err
    out = tmp_path / "compared"
    assert main(["compare", str(made[0]), str(batch), "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert len(err.strip().splitlines()) == 1 and "where the record says project" in err
    assert not (tmp_path / "page").exists() and not out.exists()
    storage.write_json(batch / BATCH_FILE, {**record, "seeds": [0]})
    with pytest.raises(ReportError, match=f"{SECOND} in .* ran with seed 1, which the record"):
        collect(batch)


def test_a_batch_s_logs_leave_out_its_unfinished_trials_and_name_them(made, tmp_path):
    batch = _copy(made, tmp_path)
    # The second trial being extended: its config.json asks for more than its logs hold.
    config = storage.read_json(batch / SECOND / CONFIG_FILE)
    config["trial"]["iterations"] = 40
    storage.write_json(batch / SECOND / CONFIG_FILE, config)
    with pytest.warns(IncompleteTrialsWarning) as warned:
        log = read_batch_logs(batch)
    assert set(log["trial"]) == {FIRST} and len(log) == 20
    (said,) = [str(w.message) for w in warned]
    assert f"{SECOND} (at iteration 20 of 40)" in said and "left out" in said
    assert "include_incomplete=True" in said and FIRST not in said
    with pytest.warns(IncompleteTrialsWarning, match="their rows are included"):
        both = read_batch_logs(batch, "iterations", include_incomplete=True)
    assert both.groupby("trial").size().to_dict() == {FIRST: 20, SECOND: 20}
    (batch / SECOND / "checkpoint.npz").unlink()
    with pytest.warns(IncompleteTrialsWarning, match=f"{SECOND} \\(no checkpoint yet\\)"):
        assert set(read_batch_logs(batch)["trial"]) == {FIRST}
