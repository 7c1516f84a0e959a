"""A batch is read only when every trial in it is whole and one of the batch: a
missing chunk or evaluation table, or a trial copied twice or of another configuration, is
refused in one line by `read_batch_logs` and `playroom report`, never pooled."""

from __future__ import annotations

import shutil

import pytest

from experiments.analysis.batch_checks import BatchMismatch
from experiments.analysis.logs import read_batch_logs
from experiments.batch_files import REPORT_FILE
from experiments.batches.runner import is_complete
from experiments.cli.main import main
from experiments.run.settings import TrialSettings
from experiments.run.trial import run_trial
from experiments.trial_dir import storage
from experiments.trial_dir.layout import LOG_DIR, STUDY_TESTS_FILE


@pytest.fixture
def batch(batches, tmp_path):
    """A copy of the tiny kinematic batch (seeds 0 and 1, 300 iterations, evaluated)."""
    out = tmp_path / "batch"
    shutil.copytree(batches["kinematic"], out)
    return out


def _report(capsys, batch) -> tuple[int, list[str]]:
    code = main(["report", str(batch), "--out", str(batch.parent / "report")])
    return code, capsys.readouterr().err.strip().splitlines()


def test_the_intact_batch_reads(batch):
    # (Its report, with every check, is tests/report/test_report.py's on the same batches.)
    assert len(read_batch_logs(batch)) == 600
    assert len(read_batch_logs(batch, "words")) == 6


def test_d3_a_missing_chunk_stops_the_batch_readers(batch, capsys):
    chunk = batch / "kinematic-random-seed0001" / LOG_DIR / "words" / "chunk-00000000.parquet"
    chunk.unlink()
    with pytest.raises(storage.CorruptFileError, match="chunk-00000000.parquet is missing"):
        read_batch_logs(batch, "words")
    code, err = _report(capsys, batch)
    assert code == 2 and len(err) == 1 and "chunk-00000000.parquet is missing" in err[0]
    assert not (batch.parent / "report" / REPORT_FILE).exists()


def test_d4_a_missing_study_table_stops_the_report_and_a_batch_rerun_evaluates_again(batch, capsys):
    trial = batch / "kinematic-random-seed0001"
    (trial / STUDY_TESTS_FILE).unlink()
    code, err = _report(capsys, batch)
    assert code == 2 and len(err) == 1
    assert STUDY_TESTS_FILE in err[0] and "playroom eval" in err[0]
    assert not is_complete(trial)


def test_d4_a_damaged_evaluation_table_is_refused(batch, capsys):
    trial = batch / "kinematic-random-seed0000"
    table = storage.read_table(trial / STUDY_TESTS_FILE)
    storage.write_table(trial / STUDY_TESTS_FILE, table.iloc[:-1])  # a row lost, still Parquet
    code, err = _report(capsys, batch)
    assert code == 2 and len(err) == 1 and STUDY_TESTS_FILE in err[0]


def test_d6_a_trial_copied_twice_is_refused_by_read_batch_logs(batch):
    shutil.copytree(batch / "kinematic-random-seed0000", batch / "kinematic-random-seed0000-copy")
    with pytest.raises(BatchMismatch, match="seed 0 appears twice"):
        read_batch_logs(batch)


def test_d6_a_trial_of_another_configuration_is_refused_by_read_batch_logs(batch):
    # Another batch's trial (another learner setting) copied in as a new seed.
    other = TrialSettings(
        iterations=300,
        seed=2,
        checkpoint_every=300,
        overrides={"learner": {"exploration_sigma": 0.05}},
    )
    run_trial(batch / "kinematic-random-seed0002", other, progress=False)
    with pytest.raises(BatchMismatch, match="differ in learner.exploration_sigma"):
        read_batch_logs(batch)
