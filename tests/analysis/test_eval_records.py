"""A trial's eval.json is checked by every reader as its data files are: one damaged (a flipped
digit that leaves valid JSON) or another trial's (copied in whole, with its tables) is refused
in one line naming it and what to do, never reported, and a batch rerun evaluates it again;
an eval.json from before it recorded its checksum is read with one warning
(experiments/trial_dir/eval_record.py)."""

from __future__ import annotations

import json
import shutil
import warnings

import pandas as pd
import pytest
from bit_flips import flip_bit, flip_number
from old_trials import as_before_eval_checksums

from experiments.analysis import cross_worlds
from experiments.analysis.results import ReportError, collect
from experiments.batch_files import REPORT_FILE
from experiments.batches.runner import is_complete
from experiments.cli.main import main
from experiments.trial_dir import eval_record, manifest, storage
from experiments.trial_dir.layout import EVAL_FILE, EVALUATION_TABLES, VOCAL_FILE

FIRST, SECOND = "kinematic-random-seed0000", "kinematic-random-seed0001"
# Random commands per ring of the report's study reference: the fewest that make a page.
REFERENCE = "20"


@pytest.fixture
def batch(batches, tmp_path):
    """A copy of the tiny kinematic batch (seeds 0 and 1, 300 iterations, evaluated)."""
    return shutil.copytree(batches["kinematic"], tmp_path / "batch")


def _report(capsys, batch) -> tuple[int, list[str]]:
    out = batch.parent / "report"
    code = main(["report", str(batch), "--out", str(out), "--study-reference-commands", REFERENCE])
    return code, capsys.readouterr().err.strip().splitlines()


def _refused(capsys, batch, said: str) -> str:
    """The one line `playroom report` and `collect` refuse the batch with, holding `said`."""
    code, err = _report(capsys, batch)
    assert code == 2 and len(err) == 1 and said in err[0], err
    assert not (batch.parent / "report" / REPORT_FILE).exists()
    with pytest.raises(ReportError) as caught:
        collect(batch)
    assert said in str(caught.value) and "\n" not in str(caught.value)
    return err[0]


def test_f1_a_flipped_digit_in_eval_json_is_refused_and_evaluated_again(batch, capsys):
    path = batch / SECOND / EVAL_FILE
    ring1 = storage.read_json(path)["competence"]["ring1"]
    flip_number(path, "ring1", ring1)
    assert storage.read_json(path)["competence"]["ring1"] != ring1  # still JSON, another number
    line = _refused(capsys, batch, f"{path} is damaged")
    assert f"playroom eval {batch / SECOND}" in line
    with pytest.raises(storage.CorruptFileError, match="is damaged"):
        cross_worlds.tested_in(
            batch / SECOND, "kinematic"
        )  # the cross-world readers (ladder, world_steps)
    assert not is_complete(batch / SECOND)  # a batch rerun evaluates it again
    assert is_complete(batch / FIRST)


def test_a_changed_byte_that_changes_no_number_read_is_refused_too(batch):
    path = batch / SECOND / EVAL_FILE
    ring1 = storage.read_json(path)["competence"]["ring1"]
    flip_bit(path, f'"ring1": {json.dumps(ring1)}')  # its last digit: maybe past a float's
    with pytest.raises(ReportError, match=f"{path} is damaged"):
        collect(batch)


def test_f2_another_trials_evaluation_copied_in_whole_is_refused(batch, capsys):
    for name in (EVAL_FILE, *EVALUATION_TABLES):  # intact, and as its eval.json lists them
        shutil.copyfile(batch / FIRST / name, batch / SECOND / name)
    path = batch / SECOND / EVAL_FILE
    line = _refused(capsys, batch, f"{path} is the evaluation of another trial (seed 0")
    assert "than the one it lies in (seed 1" in line and "playroom eval" in line
    assert not is_complete(batch / SECOND)


def test_f2_an_evaluation_of_the_same_seed_and_grasp_but_another_config_is_refused(batch):
    # A trial of other settings, of seed 1: only the identity (a hash of the config) tells.
    config_path = batch / SECOND / "config.json"
    other = storage.read_json(config_path)
    other["learner"]["exploration_sigma"] = 0.05
    summary = storage.read_json(batch / SECOND / EVAL_FILE)
    summary.pop(eval_record.CHECKSUM_KEY)  # written again whole, as the other trial's writer would
    (batch / SECOND / EVAL_FILE).write_bytes(eval_record.evaluation_json(summary, other))
    with pytest.raises(ReportError, match=r"evaluation of another trial \(seed 1, config "):
        collect(batch)


def test_f4_a_damaged_eval_json_is_named_not_the_table_it_lists(batch, capsys):
    path = batch / SECOND / EVAL_FILE
    vocal_sha256 = storage.read_json(path)["files"][VOCAL_FILE][1]
    flip_bit(path, vocal_sha256)  # the intact vocal.parquet no longer matches what is listed
    line = _refused(capsys, batch, f"{path} is damaged")
    assert VOCAL_FILE not in line


def test_an_eval_json_from_before_checksums_is_read_with_one_warning(batch):
    expected = collect(batch).trials
    for name in (FIRST, SECOND):
        as_before_eval_checksums(batch / name)
        assert eval_record.CHECKSUM_KEY not in storage.read_json(batch / name / EVAL_FILE)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        found = collect(batch).trials
    unchecked = [w for w in caught if issubclass(w.category, manifest.UncheckedEvaluationWarning)]
    assert len(unchecked) == 1, [str(w.message) for w in caught]
    assert "2 trial(s) of" in str(unchecked[0].message) and "playroom eval" in str(
        unchecked[0].message
    )
    pd.testing.assert_frame_equal(found, expected)
    # Its seed and grasp are still compared: another trial's is refused, checksum or none.
    shutil.copyfile(batch / FIRST / EVAL_FILE, batch / SECOND / EVAL_FILE)
    with pytest.raises(ReportError, match="evaluation of another trial"):
        collect(batch)
