"""Every reader checks what a trial wrote: a data file damaged, missing, replaced or
stray is refused in one line naming it by every reader (the Python API, eval, resume, batch,
report), never read into a number; the manifest survives a kill at its own write; a trial
keeps the name it was created as; a lost backend.json is regenerated when it can be."""

from __future__ import annotations

import dataclasses
import shutil
import warnings

import pytest
from old_trials import as_before_manifests
from test_trial_integrity import _cli, _contents, _copy
from trial_states import same_state

from experiments.analysis.logs import read_log
from experiments.batches.runner import is_complete, run_and_evaluate
from experiments.measure.evaluation import EvaluationSettings
from experiments.measure.trial_evaluation import evaluate_trial
from experiments.run.settings import TrialSettings
from experiments.run.trial import run_trial
from experiments.run.trial_parts import load_trial
from experiments.trial_dir import backend_record, manifest, storage
from experiments.trial_dir.errors import TrialError
from experiments.trial_dir.layout import (
    BACKEND_FILE,
    CHECKPOINT_FILE,
    LOG_DIR,
    MANIFEST_DIR,
    MEMORY_DIR,
    PREVIOUS_CHECKPOINT_FILE,
)

SEED, TOTAL, PERIOD = 4, 300, 100
# The project preset stores memory rows from the first iteration: every period has a segment.
SETTINGS = TrialSettings(iterations=TOTAL, seed=SEED, checkpoint_every=PERIOD, preset="project")
CHUNK = f"{LOG_DIR}/iterations/chunk-00000100.parquet"


@pytest.fixture(scope="module")
def base(tmp_path_factory):
    """A finished, evaluated trial (300 iterations, checkpoints every 100); tests copy it."""
    out = tmp_path_factory.mktemp("manifest") / "trial"
    run_trial(out, SETTINGS, progress=False)
    evaluate_trial(out, EvaluationSettings(n_placements=1))
    return out


def _xor_middle(path, count: int = 64) -> None:
    """`count` bytes in the middle of a file inverted: its footer (and so its format) intact."""
    data = bytearray(path.read_bytes())
    middle = len(data) // 2
    for i in range(middle, middle + count):
        data[i] ^= 0xFF
    path.write_bytes(bytes(data))


def _resume(out, iterations: int) -> list[str]:
    return ["run", "--out", str(out), "--resume", "--quiet", "--iterations", str(iterations)]


def test_every_data_file_is_recorded_with_its_size_and_checksum(base):
    recorded = manifest.trial_manifest(base)
    assert recorded is not None and recorded.iteration == TOTAL
    on_disk = {manifest.relative(base, p) for p in manifest.data_files(base)}
    assert set(recorded.files) == on_disk
    assert {BACKEND_FILE, CHUNK, f"{MEMORY_DIR}/rows-00000100.npz"} <= on_disk
    for name, entry in recorded.files.items():
        assert manifest.entry_of((base / name).read_bytes()) == entry
    # One small file per checkpoint, at 0, 100, 200 and 300.
    assert len(list((base / MANIFEST_DIR).iterdir())) == 4


def test_d2_a_damaged_chunk_is_refused_by_every_reader(base, tmp_path, capsys):
    out = _copy(base, tmp_path)
    _xor_middle(out / CHUNK)
    before = _contents(out)
    with pytest.raises(storage.CorruptFileError, match="chunk-00000100.parquet is damaged"):
        read_log(out)
    for argv in (["eval", str(out), "--quiet", "--placements", "1"], _resume(out, TOTAL + 50)):
        code, err = _cli(capsys, *argv)
        assert code == 2 and len(err) == 1, err
        assert "chunk-00000100.parquet" in err[0] and "damaged" in err[0]
    assert not is_complete(out)
    assert _contents(out) == before


def test_d3_a_missing_chunk_is_refused_by_the_api_too(base, tmp_path):
    out = _copy(base, tmp_path)
    (out / CHUNK).unlink()
    with pytest.raises(storage.CorruptFileError, match="chunk-00000100.parquet is missing"):
        read_log(out)
    with pytest.raises(storage.CorruptFileError, match="chunk-00000100.parquet is missing"):
        read_log(out, columns=["model"])


def test_a_stray_chunk_before_the_checkpoint_is_refused(base, tmp_path):
    out = _copy(base, tmp_path)
    shutil.copy(out / CHUNK, out / LOG_DIR / "iterations" / "chunk-00000150.parquet")
    with pytest.raises(storage.CorruptFileError, match="chunk-00000150.parquet is not among"):
        read_log(out)
    with pytest.raises(TrialError, match="chunk-00000150.parquet is not among"):
        load_trial(out)


def test_a_damaged_memory_segment_is_refused(base, tmp_path, capsys):
    out = _copy(base, tmp_path)
    _xor_middle(out / MEMORY_DIR / "rows-00000100.npz", 8)
    code, err = _cli(capsys, "eval", str(out), "--quiet", "--placements", "1")
    assert code == 2 and len(err) == 1 and "rows-00000100.npz" in err[0]


def test_a_damaged_manifest_file_is_refused(base, tmp_path, capsys):
    out = _copy(base, tmp_path)
    path = out / MANIFEST_DIR / "files-00000200.json"
    path.write_text(path.read_text().replace('"previous"', '"previous" '))
    with pytest.raises(storage.CorruptFileError, match="files-00000200.json is damaged"):
        read_log(out)
    code, err = _cli(capsys, "eval", str(out), "--quiet", "--placements", "1")
    assert code == 2 and len(err) == 1 and "files-00000200.json" in err[0]


def test_killed_after_the_manifest_before_its_checkpoint_resumes_to_the_same(base, tmp_path):
    # The run killed between the manifest of iteration 300 and its checkpoint: the newest
    # checkpoint is 200's, and files-00000300.json lies past it, named by nothing.
    out = _copy(base, tmp_path)
    (out / CHECKPOINT_FILE).unlink()
    shutil.move(out / PREVIOUS_CHECKPOINT_FILE, out / CHECKPOINT_FILE)
    assert (out / MANIFEST_DIR / "files-00000300.json").exists()
    assert read_log(out)["iteration"].max() == 199  # the work past it is not vouched for
    notices: list[str] = []
    run_trial(out, SETTINGS, resume=True, progress=False, notify=notices.append)
    same_state(out, base)
    assert manifest.trial_manifest(out).files == manifest.trial_manifest(base).files


def test_d11_a_moved_trial_keeps_the_name_it_was_created_as(tmp_path):
    first = tmp_path / "r9-orig"
    run_trial(first, TrialSettings(iterations=200, seed=1, checkpoint_every=PERIOD), False)
    moved = tmp_path / "r9-moved"
    shutil.move(first, moved)
    run_trial(moved, TrialSettings(iterations=400, seed=1, checkpoint_every=PERIOD), True, False)
    assert read_log(moved)["trial"].unique().tolist() == ["r9-orig"]
    assert read_log(moved, "words")["trial"].unique().tolist() == ["r9-orig"]


def test_d12_a_garbled_backend_json_is_refused_then_regenerated_by_a_resume(base, tmp_path, capsys):
    out = _copy(base, tmp_path)
    original = (out / BACKEND_FILE).read_bytes()
    (out / BACKEND_FILE).write_bytes(original.replace(b'"reach"', b'"reahc"'))
    code, err = _cli(capsys, "eval", str(out), "--quiet", "--placements", "1")
    assert code == 2 and len(err) == 1
    assert BACKEND_FILE in err[0] and "--resume` regenerates it" in err[0]
    assert not is_complete(out)
    code, err = _cli(capsys, *_resume(out, TOTAL))
    assert code == 0 and any("regenerated" in line for line in err), err
    assert (out / BACKEND_FILE).read_bytes() == original
    assert is_complete(out)


def test_d12_a_backend_json_the_backend_no_longer_declares_is_refused(base, tmp_path, capsys):
    out = _copy(base, tmp_path)
    (out / BACKEND_FILE).unlink()
    before = _contents(out)
    real = backend_record.make_record

    def declares_otherwise(grasp, reach, capabilities):  # as if the code had changed since
        return real(grasp, reach + 0.01, capabilities)

    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(backend_record, "make_record", declares_otherwise)
        code, err = _cli(capsys, *_resume(out, TOTAL))
    assert code == 2 and len(err) == 1
    assert BACKEND_FILE in err[0] and "cannot be regenerated" in err[0]
    assert _contents(out) == before


def test_d2_d3_a_batch_task_reruns_what_can_be_mended_and_names_what_cannot(base, tmp_path):
    out = _copy(base, tmp_path)
    (out / CHUNK).unlink()
    result = run_and_evaluate(str(out), SETTINGS, eval_placements=1)
    assert "chunk-00000100.parquet is missing" in getattr(result, "error", "")


def test_a_trial_from_before_manifests_reads_with_one_warning_and_a_resume_records_one(
    base, tmp_path
):
    out = _copy(base, tmp_path)
    as_before_manifests(out)
    with pytest.warns(manifest.UncheckedTrialWarning, match="read unchecked") as caught:
        read_log(out)
    assert len(caught) == 1
    run_trial(out, dataclasses.replace(SETTINGS, iterations=TOTAL + PERIOD), True, False)
    with warnings.catch_warnings():
        warnings.simplefilter("error", manifest.UncheckedTrialWarning)
        recorded = manifest.trial_manifest(out)
    assert recorded is not None
    assert set(recorded.files) == {manifest.relative(out, p) for p in manifest.data_files(out)}
