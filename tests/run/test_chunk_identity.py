"""Every log chunk carries its trial's identity (the seed and the config's hash, as checkpoints
do): a chunk of another trial copied into a trial is refused by a resume, an evaluation, a
batch rerun and the readers, with one line naming the file and both identities; chunks written
before chunks carried one are read and resumed as before."""

from __future__ import annotations

import json
import shutil

import pyarrow.parquet as pq
import pytest
from old_trials import as_before_manifests
from test_trial_integrity import task_failure
from trial_logs import same_logs

from experiments.analysis.logs import read_batch_logs, read_log
from experiments.batches.runner import is_complete
from experiments.cli.main import main
from experiments.run.settings import TrialSettings
from experiments.run.trial import run_trial
from experiments.trial_dir import storage
from experiments.trial_dir.checks import chunk_identity
from experiments.trial_dir.config_file import trial_identity
from experiments.trial_dir.layout import (
    CHUNK_IDENTITY_KEY,
    CONFIG_FILE,
    LOCK_FILE,
    LOG_DIR,
    LOG_KINDS,
)

TOTAL, PERIOD = 300, 100
OWN, OTHER = 5, 6  # the seeds
FOREIGN = "chunk-00000100.parquet"


def _settings(seed: int, total: int = TOTAL) -> TrialSettings:
    return TrialSettings(iterations=total, seed=seed, checkpoint_every=PERIOD)


@pytest.fixture(scope="module")
def trials(tmp_path_factory):
    """Two finished trials of the same settings but their seeds, checkpoints every 100."""
    root = tmp_path_factory.mktemp("two")
    for seed in (OWN, OTHER):
        run_trial(root / f"seed{seed}", _settings(seed), progress=False)
    return root


def _copy(trials, tmp_path, seed: int = OWN):
    out = tmp_path / "batch" / f"seed{seed}"
    shutil.copytree(trials / f"seed{seed}", out)
    return out


def _contents(out) -> dict:
    return {p: p.read_bytes() for p in out.rglob("*") if p.is_file() and p.name != LOCK_FILE}


def _identity(out) -> dict:
    return trial_identity(storage.read_json(out / CONFIG_FILE))


def test_every_chunk_carries_its_trials_identity(trials):
    out = trials / f"seed{OWN}"
    for kind in LOG_KINDS:
        chunks = sorted((out / LOG_DIR / kind).glob("*.parquet"))
        assert chunks
        for chunk in chunks:
            assert chunk_identity(chunk) == _identity(out)
            attrs = json.loads(pq.read_schema(chunk).metadata[b"PANDAS_ATTRS"])
            assert attrs[CHUNK_IDENTITY_KEY] == _identity(out)  # in the schema's metadata


def test_a_chunk_of_another_trial_is_refused_everywhere(trials, tmp_path, capsys):
    out = _copy(trials, tmp_path)
    for kind in LOG_KINDS:  # the copy: both kinds of one period, from seed 6
        shutil.copy(trials / f"seed{OTHER}" / LOG_DIR / kind / FOREIGN, out / LOG_DIR / kind)
    own, other = _identity(out), _identity(trials / f"seed{OTHER}")
    before = _contents(out)

    def says(line: str) -> None:
        assert FOREIGN in line and "another trial" in line, line
        assert f"seed {other['seed']}, config {other['config']}" in line, line
        assert f"seed {own['seed']}, config {own['config']}" in line, line

    assert main(["eval", str(out), "--quiet", "--placements", "1"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1
    says(err[0])
    resume = ["run", "--out", str(out), "--resume", "--quiet", "--iterations", str(TOTAL + 100)]
    assert main(resume) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1
    says(err[0])
    assert not is_complete(out)
    says(task_failure(out, _settings(OWN)))  # a batch rerun's task
    for kind in LOG_KINDS:
        with pytest.raises(storage.CorruptFileError) as exc:
            read_log(out, kind)
        says(str(exc.value))
    with pytest.raises(storage.CorruptFileError, match="another trial"):
        read_batch_logs(out.parent)
    assert _contents(out) == before


def test_chunks_written_before_chunks_carried_an_identity_are_read_and_resumed(
    trials, tmp_path, capsys
):
    out = _copy(trials, tmp_path)
    as_before_manifests(out)  # which came after identities
    for kind in LOG_KINDS:  # as the code before wrote them: no identity in the schema
        for chunk in (out / LOG_DIR / kind).glob("*.parquet"):
            table = storage.read_table(chunk)
            table.attrs.clear()
            storage.write_table(chunk, table)
            assert chunk_identity(chunk) is None
    same_logs(out, trials / f"seed{OWN}")
    assert main(["eval", str(out), "--quiet", "--placements", "1"]) == 0
    capsys.readouterr()
    longer = tmp_path / "longer"
    run_trial(longer, _settings(OWN, TOTAL + PERIOD), progress=False)
    run_trial(out, _settings(OWN, TOTAL + PERIOD), resume=True, progress=False)
    same_logs(out, longer)
    new = out / LOG_DIR / "iterations" / f"chunk-{TOTAL:08d}.parquet"
    assert chunk_identity(new) == _identity(out)  # the resumed run's chunks carry one
    assert read_log(out)["seed"].eq(OWN).all()
