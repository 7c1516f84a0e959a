"""Provenance: each trial records the machine, libraries and commit that computed it; a resume
elsewhere says so; evaluations, reports and comparisons show where trials ran."""

from __future__ import annotations

import dataclasses
import datetime
import html
import json
import platform
import shutil
import subprocess
from importlib.metadata import version
from pathlib import Path

import numpy as np
import pytest
import threadpoolctl

import experiments
from experiments.cli.main import main
from experiments.measure.for_reports import room_measures
from experiments.report.batch_report import write_report
from experiments.run.settings import TrialSettings
from experiments.run.trial import run_trial
from experiments.trial_dir import provenance, storage
from experiments.trial_dir.layout import (
    CONFIG_FILE,
    DAMAGED_PROVENANCE_FILE,
    EVAL_FILE,
    PROVENANCE_FILE,
)
from experiments.trial_dir.provenance import (
    bit_differences,
    describe,
    machine_record,
    short_record,
    source_record,
)
from experiments.trial_dir.provenance_file import computed_on_line, read_entries

SOURCE_ROOT = Path(experiments.__file__).resolve().parents[1]
SHORT = TrialSettings(grasp="kinematic", iterations=100, seed=3, checkpoint_every=100)
LONGER = TrialSettings(grasp="kinematic", iterations=200, seed=3, checkpoint_every=100)


def _git(*args: str) -> str:
    return subprocess.run(
        ["git", "-C", str(SOURCE_ROOT), *args], capture_output=True, text=True, check=True
    ).stdout.strip()


@pytest.fixture(scope="module")
def short_trial(tmp_path_factory) -> Path:
    """A 100-iteration trial, run once; tests copy it before writing into it."""
    trial = tmp_path_factory.mktemp("provenance") / "trial"
    run_trial(trial, SHORT, progress=False)
    return trial


@pytest.fixture
def trial_copy(short_trial, tmp_path) -> Path:
    shutil.copytree(short_trial, tmp_path / "trial")
    return tmp_path / "trial"


def _elsewhere(record: dict) -> dict:
    """The record as another machine with another NumPy would give it."""
    other = json.loads(json.dumps(record))
    other["cpu"]["model"] = "Imaginary CPU 9000"
    other["versions"]["numpy"] = "0.0.1"
    other["host"] = "elsewhere"
    return other


# The record ----------------------------------------------------------------------------------
def test_the_record_holds_this_machines_real_values(monkeypatch):
    monkeypatch.setenv("OPENBLAS_CORETYPE", "Haswell")
    monkeypatch.delenv("NUMBA_CPU_NAME", raising=False)  # set where another CPU is emulated
    record = machine_record()
    versions = record["versions"]
    assert versions["numpy"] == np.__version__
    assert versions["python"] == platform.python_version()
    for name in ("mujoco", "dm-control", "scipy", "numba", "vocaltractlab-cython", "playroom"):
        assert versions[name] == version(name)
    assert record["environment"]["OPENBLAS_CORETYPE"] == "Haswell"
    assert "NUMBA_CPU_NAME" not in record["environment"]  # only variables that are set
    from numpy._core._multiarray_umath import __cpu_baseline__, __cpu_dispatch__, __cpu_features__

    assert record["simd"]["baseline"] == list(__cpu_baseline__)
    assert record["simd"]["dispatched"] == [f for f in __cpu_dispatch__ if __cpu_features__[f]]
    loaded = [i for i in threadpoolctl.threadpool_info() if i["user_api"] == "blas"]
    assert record["blas"] and {b["kernel"] for b in record["blas"]} <= {
        i["architecture"] for i in loaded
    }
    assert record["cpu"]["model"] and record["cpu"]["machine"] == platform.machine()
    assert record["host"] == platform.node()
    recorded = datetime.datetime.fromisoformat(record["recorded_at"])
    assert recorded.utcoffset() == datetime.timedelta(0)
    json.dumps(record, allow_nan=False)  # it goes into a JSON file


def test_the_record_names_the_commit_of_the_checkout_it_was_imported_from():
    if not (SOURCE_ROOT / ".git").exists():
        pytest.skip("the package is not imported from a git checkout here")
    source = source_record()
    assert source["where"] == "git checkout"
    assert source["commit"] == _git("rev-parse", "HEAD")
    assert source["dirty"] == bool(_git("status", "--porcelain", "--untracked-files=no"))


def test_outside_a_checkout_or_without_git_the_record_says_so(tmp_path, monkeypatch):
    assert source_record(tmp_path) == {"commit": None, "dirty": None, "where": "installed package"}
    monkeypatch.setenv("PATH", str(tmp_path))  # no git on it
    source = source_record()
    assert source["commit"] is None and source["where"].startswith("unknown")
    assert machine_record()["source"] == source  # the record is still made
    monkeypatch.undo()
    (tmp_path / "refused" / ".git").mkdir(parents=True)  # a checkout git cannot read
    assert source_record(tmp_path / "refused")["where"].startswith("unknown (git: ")


def test_a_hand_edited_record_of_missing_sections_is_still_shown_and_compared():
    edited = {"host": "h", "cpu": None, "simd": [], "blas": "?", "source": None}
    assert describe(short_record(edited)).startswith("h (None, SIMD none, none, numpy None")
    assert "numpy None -> " + np.__version__ in bit_differences(edited, machine_record())


def test_what_counts_as_a_change_of_machine_or_libraries():
    record = machine_record()
    same = json.loads(json.dumps(record))
    same["host"], same["recorded_at"] = "another-name", "2000-01-01T00:00:00+00:00"
    same["source"]["dirty"] = not record["source"]["dirty"]
    same["cpu"]["cores"] = 512
    same["versions"]["pandas"] = "0.0.0"  # stores results, computes none
    assert bit_differences(record, same) == []
    changed = _elsewhere(record)
    # Values no real machine has, so that the test holds under any emulated CPU (make test-slow).
    changed["blas"] = [{**b, "kernel": "ImaginaryKernel"} for b in record["blas"]]
    features = "AVX512_IMAGINARY"
    changed["environment"] = {**record["environment"], "NPY_DISABLE_CPU_FEATURES": features}
    changes = bit_differences(record, changed)
    assert any(c.startswith("CPU ") and "Imaginary CPU 9000" in c for c in changes)
    assert f"numpy {np.__version__} -> 0.0.1" in changes
    assert any(c.startswith("BLAS ") and "ImaginaryKernel" in c for c in changes)
    before = record["environment"].get("NPY_DISABLE_CPU_FEATURES", "unset")
    assert f"NPY_DISABLE_CPU_FEATURES {before} -> {features}" in changes
    assert len(changes) == 4
    if record["source"]["commit"]:
        other_commit = json.loads(json.dumps(record))
        other_commit["source"]["commit"] = "0" * 40
        assert [c.split()[0] for c in bit_differences(record, other_commit)] == ["commit"]


# The trial writes it -------------------------------------------------------------------------
def test_a_new_trial_records_its_machine_outside_its_config(short_trial):
    entries = read_entries(short_trial)
    assert [e["from_iteration"] for e in entries] == [0]
    record = entries[0]["record"]
    assert record["versions"]["numpy"] == np.__version__
    assert bit_differences(record, machine_record()) == []
    config = storage.read_json(short_trial / CONFIG_FILE)
    assert "package_version" in config and "provenance" not in json.dumps(config)


def test_a_resume_on_another_machine_appends_its_entry_and_says_what_changed(
    trial_copy, monkeypatch
):
    real = machine_record
    monkeypatch.setattr(provenance, "machine_record", lambda: _elsewhere(real()))
    said: list[str] = []
    trial = run_trial(trial_copy, LONGER, resume=True, progress=False, notify=said.append)
    entries = read_entries(trial_copy)
    assert [e["from_iteration"] for e in entries] == [0, 100]
    assert entries[1]["record"]["cpu"]["model"] == "Imaginary CPU 9000"
    changed = [line for line in trial.notices if "machine or libraries changed" in line]
    assert len(changed) == 1 and changed == [line for line in said if line in changed]
    assert "Imaginary CPU 9000" in changed[0] and "numpy" in changed[0]
    assert "\n" not in changed[0] and "host" not in changed[0]
    assert "elsewhere" in computed_on_line(trial_copy)


def test_a_resume_on_the_same_machine_appends_without_a_notice(trial_copy):
    trial = run_trial(trial_copy, LONGER, resume=True, progress=False)
    assert trial.notices == []
    entries = read_entries(trial_copy)
    assert [e["from_iteration"] for e in entries] == [0, 100]
    assert bit_differences(entries[0]["record"], entries[1]["record"]) == []
    # One machine, one stretch: the line names it once.
    assert computed_on_line(trial_copy).count(" from iteration ") == 1


def test_an_extension_keeps_provenance_in_place_and_moves_only_derived_files(trial_copy):
    storage.write_json(trial_copy / EVAL_FILE, {"derived": True})
    run_trial(trial_copy, LONGER, resume=True, progress=False)
    assert (trial_copy / "stale-at-00000100" / EVAL_FILE).exists()
    assert not (trial_copy / "stale-at-00000100" / PROVENANCE_FILE).exists()
    assert len(read_entries(trial_copy)) == 2


def test_entries_of_discarded_work_are_dropped_and_older_trials_say_not_recorded(trial_copy):
    entries = read_entries(trial_copy)
    # An entry from iteration 150: a run killed before its next checkpoint; lost on resume.
    storage.write_json(
        trial_copy / PROVENANCE_FILE, [*entries, {**entries[0], "from_iteration": 150}]
    )
    run_trial(trial_copy, LONGER, resume=True, progress=False)
    assert [e["from_iteration"] for e in read_entries(trial_copy)] == [0, 100]
    older = trial_copy.parent / "older"
    shutil.copytree(trial_copy, older)
    (older / PROVENANCE_FILE).unlink()
    assert computed_on_line(older).startswith("computed on: not recorded")
    run_trial(older, dataclasses.replace(LONGER, iterations=300), resume=True, progress=False)
    entries = read_entries(older)
    assert [(e["from_iteration"], e["record"] is None) for e in entries] == [
        (0, True),
        (200, False),
    ]
    assert computed_on_line(older).startswith("computed on not recorded from iteration 0; ")


def test_a_damaged_provenance_is_kept_aside_and_said(trial_copy):
    (trial_copy / PROVENANCE_FILE).write_text('[{"from_iteration": 0, "rec')
    trial = run_trial(trial_copy, LONGER, resume=True, progress=False)
    assert (trial_copy / DAMAGED_PROVENANCE_FILE).read_text() == '[{"from_iteration": 0, "rec'
    assert any(DAMAGED_PROVENANCE_FILE in line for line in trial.notices)
    assert [e["from_iteration"] for e in read_entries(trial_copy)] == [0, 100]


# Evaluation, eval's line, reports -------------------------------------------------------------
def test_eval_records_where_it_ran_and_prints_where_the_trial_was_computed(trial_copy, capsys):
    assert main(["eval", str(trial_copy), "--placements", "1", "--quiet"]) == 0
    out = capsys.readouterr().out.splitlines()
    here = short_record(machine_record())
    assert storage.read_json(trial_copy / EVAL_FILE)["evaluated_on"] == here
    assert out[1] == f"  computed on {describe(here)} from iteration 0"


def _batch_of_two_machines(batches: dict[str, Path], target: Path) -> Path:
    """The kinematic batch, one trial moved to another machine, one from before provenance."""
    for trial in batches["kinematic"].iterdir():
        if trial.is_dir():
            shutil.copytree(trial, target / trial.name)
    first, second = sorted(d for d in target.iterdir() if d.is_dir())
    (first / PROVENANCE_FILE).unlink()
    entries = read_entries(second)
    storage.write_json(
        second / PROVENANCE_FILE,
        [*entries, {"from_iteration": 100, "record": _elsewhere(entries[0]["record"])}],
    )
    return target


def test_the_report_shows_where_its_trials_ran(batches, tmp_path):
    batch = _batch_of_two_machines(batches, tmp_path / "batch")
    page = write_report(batch, tmp_path / "out", measures=room_measures(20)).read_text()
    section = html.unescape(page.split("<h2>Where the trials ran</h2>")[1].split("<h2>")[0])
    here = short_record(machine_record())
    rows = section.split("<tr>")[2:]  # after the header
    cells = [[c.split("</td>")[0] for c in row.split("<td>")[1:]] for row in rows]
    by_cpu = {row[0]: row for row in cells}
    assert set(by_cpu) == {here["cpu"], "Imaginary CPU 9000", "not recorded (older trials)"}
    # Computed here: the second trial up to iteration 100; evaluated here: both.
    assert by_cpu[here["cpu"]][5:] == [here["host"], here["commit"], "1", "2"]
    assert by_cpu["Imaginary CPU 9000"][3] == "0.0.1" and by_cpu["Imaginary CPU 9000"][7:] == [
        "1",
        "0",
    ]
    assert by_cpu["not recorded (older trials)"][7:] == ["1", "0"]
    assert "1 trial changed machine or library set on a resume and counts under each" in section
