"""A trial's records (experiments/trial_dir/records.py): the summary a finished trial writes,
recorded and checked like backend.json by every reader that checks a trial whole, regenerated
by a resume when lost or damaged; a record kind added to the declaration is checked by them
without a line of theirs changed."""

from __future__ import annotations

import json
import os

import numpy as np
import pytest
from test_trial_integrity import _cli, _copy

from experiments.analysis.logs import read_log
from experiments.batches.runner import is_complete
from experiments.run.settings import TrialSettings
from experiments.run.trial import run_trial
from experiments.run.trial_parts import load_trial
from experiments.trial_dir import layout, manifest, records, storage
from experiments.trial_dir.errors import TrialError
from experiments.trial_dir.log_schema import SOURCE_COLUMNS
from experiments.trial_dir.reading import open_for_reading

SEED, TOTAL, PERIOD = 5, 200, 100
SETTINGS = TrialSettings(iterations=TOTAL, seed=SEED, checkpoint_every=PERIOD)
SUMMARY = layout.RECORDS["summary"]


@pytest.fixture(scope="module")
def finished(tmp_path_factory):
    out = tmp_path_factory.mktemp("records") / "trial"
    run_trial(out, SETTINGS, progress=False)
    return out


def test_a_finished_trial_summarises_where_it_ended(finished):
    summary = open_for_reading(finished).record("summary")
    meta = storage.read_meta(finished / layout.CHECKPOINT_FILE)
    assert summary["iteration"] == TOTAL == meta["iteration"]
    assert summary["counts"] == meta["counts"]
    # The best distance to each word: the last row of the words log, in the voice's order.
    words = read_log(finished, "words").drop(columns=list(SOURCE_COLUMNS))
    last = words.drop(columns="iteration").iloc[-1].to_numpy(dtype=float)
    reached = [np.inf if d is None else d for d in summary["best_word_distance"]]
    np.testing.assert_array_equal(reached, last)
    assert SUMMARY in manifest.trial_manifest(finished).files  # recorded by the last checkpoint


def test_a_summary_past_the_checkpoint_is_not_the_trials(finished, tmp_path):
    # Killed between its last period's files and its checkpoint: the newest checkpoint is the
    # one at iteration 100, whose manifest records no summary; the one on disk is past it.
    out = _copy(finished, tmp_path)
    os.replace(out / layout.PREVIOUS_CHECKPOINT_FILE, out / layout.CHECKPOINT_FILE)
    assert (out / SUMMARY).exists()
    assert open_for_reading(out).record("summary") is None
    load_trial(out)  # the trial at 100 is whole: what lies past it is not read
    run_trial(out, SETTINGS, resume=True, progress=False)
    assert (out / SUMMARY).read_bytes() == (finished / SUMMARY).read_bytes()


def test_a_damaged_summary_is_refused_then_regenerated_by_a_resume(finished, tmp_path, capsys):
    out = _copy(finished, tmp_path)
    original = (out / SUMMARY).read_bytes()
    (out / SUMMARY).write_bytes(original.replace(b'"iteration": 200', b'"iteration": 201'))
    with pytest.raises(TrialError, match=f"{SUMMARY}.*--resume` regenerates it"):
        load_trial(out)
    assert not is_complete(out)  # a batch reruns the task that mends it
    code, err = _cli(capsys, "run", "--out", str(out), "--resume", "--quiet")
    assert code == 0 and any("regenerated" in line for line in err), err
    assert (out / SUMMARY).read_bytes() == original
    load_trial(out)


def test_a_record_kind_added_to_the_declaration_is_checked_without_another_edit(
    finished, tmp_path, monkeypatch
):
    """A new kind, declared as the summary is, written by a run as the summary is: the readers
    that check a trial whole refuse it damaged, though none of them names it."""
    monkeypatch.setitem(layout.RECORDS, "extra", "extra.json")
    write_new = records.write_new

    def with_extra(trial_dir, kind, record, unrecorded):  # the code that computes the new one
        write_new(trial_dir, kind, record, unrecorded)
        if kind == "summary":
            write_new(trial_dir, "extra", {"from": "a newer version"}, unrecorded)

    monkeypatch.setattr(records, "write_new", with_extra)
    out = tmp_path / "trial"
    run_trial(out, SETTINGS, progress=False)
    assert "extra.json" in manifest.trial_manifest(out).files
    assert json.loads((out / "extra.json").read_text()) == {"from": "a newer version"}
    load_trial(out)
    (out / "extra.json").write_text('{"from": "someone else"}')
    with pytest.raises(TrialError, match="extra.json"):
        load_trial(out)
    assert not is_complete(out)


def test_an_extended_trial_summarises_its_new_end(finished, tmp_path):
    out = _copy(finished, tmp_path)
    longer = TrialSettings(iterations=TOTAL + PERIOD, seed=SEED, checkpoint_every=PERIOD)
    run_trial(out, longer, resume=True, progress=False)
    summary = open_for_reading(out).record("summary")
    assert summary["iteration"] == TOTAL + PERIOD
    assert summary["counts"] == storage.read_meta(out / layout.CHECKPOINT_FILE)["counts"]
    load_trial(out)
