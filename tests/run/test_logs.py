"""Logs that load in one line: each kind in its own folder, every row naming its trial, the
learner's goals, outcomes and interests logged, one loader for a trial and one for a batch,
and trials of the old layout (chunks side by side in log/) still resumed, evaluated and read."""

from __future__ import annotations

import shutil

import numpy as np
import pandas as pd
import pytest
from old_trials import as_before_manifests
from trial_logs import logs_of

from experiments.analysis.logs import read_batch_logs, read_log
from experiments.analysis.results import collect
from experiments.batches.runner import is_complete
from experiments.measure.evaluation import EvaluationSettings
from experiments.measure.trial_evaluation import evaluate_trial
from experiments.run.settings import TrialSettings
from experiments.run.trial import run_trial
from experiments.trial_dir import storage
from experiments.trial_dir.checks import DuplicateChunkError, check_logs, listed_chunks
from experiments.trial_dir.config_file import source_of, trial_identity
from experiments.trial_dir.errors import TrialError
from experiments.trial_dir.layout import LOG_DIR, LOG_README_FILE
from experiments.trial_dir.log_schema import (
    GOAL_COLUMNS,
    INTEREST_COLUMNS,
    KINDS,
    LEARNER_COLUMNS,
    REACHED_COLUMNS,
    SOURCE_COLUMNS,
    WORD,
    column_names,
)
from experiments.trial_dir.reading import open_for_reading
from learner.config import learner_preset

# Short trials: a bootstrap of 10 random commands, then goals, under active babbling.
SHORT_LEARNER = {"learner": {"bootstrap_arm": 5, "bootstrap_voice": 5}}


def _settings(iterations: int, seed: int = 2, **kwargs) -> TrialSettings:
    kwargs = {"checkpoint_every": 40, "babbling": "active", **kwargs}
    return TrialSettings(
        iterations=iterations, seed=seed, preset="project", overrides=SHORT_LEARNER, **kwargs
    )


@pytest.fixture(scope="module")
def trial(tmp_path_factory):
    """120 kinematic iterations in chunks of 40 (the words row at 100 in the last)."""
    out = tmp_path_factory.mktemp("logs") / "kinematic-seed2"
    run_trial(out, _settings(120), progress=False)
    return out


def test_each_kind_reads_in_one_line_and_the_whole_folder_does_not(trial):
    iterations = pd.read_parquet(trial / LOG_DIR / "iterations")
    assert list(iterations["iteration"]) == list(range(120))  # once each, in order
    assert iterations["motor_space"].notna().all()
    pd.testing.assert_frame_equal(iterations, read_log(trial))
    words = pd.read_parquet(trial / LOG_DIR / "words")
    assert list(words["iteration"]) == [100]
    assert {"oey", "uye", "iuo", "eyu", "eou", "yeo"} <= set(words.columns)
    pd.testing.assert_frame_equal(words, read_log(trial, "words"))
    # A reader of the whole of log/ stops on the file that says which folder to read.
    with pytest.raises(Exception, match=LOG_README_FILE):
        pd.read_parquet(trial / LOG_DIR)
    readme = (trial / LOG_DIR / LOG_README_FILE).read_text()
    assert 'pd.read_parquet("TRIAL/log/iterations")' in readme


def test_the_chunks_hold_the_declared_columns_in_order_and_type(trial):
    words = list(storage.read_json(trial / "config.json")["voice"]["words"])
    for kind, expected in (
        ("iterations", list(column_names("iterations"))),
        ("words", [*column_names("words"), *words]),
    ):
        declared = {n: c.dtype for c in (*KINDS[kind], WORD) for n in c.names}
        for chunk in sorted((trial / LOG_DIR / kind).glob("*.parquet")):
            table = pd.read_parquet(chunk)
            assert list(table.columns) == expected, chunk.name
            types = {c: declared.get(c, WORD.dtype) for c in table.columns}
            assert {c: str(t) for c, t in table.dtypes.items()} == types, chunk.name


def test_a_reader_of_a_few_columns_gets_them_as_the_whole_log_holds_them(trial):
    whole = read_log(trial)
    wanted = ["motor_space", "diverged", "no_such_column", "iteration"]
    few = read_log(trial, columns=wanted)
    held = [*SOURCE_COLUMNS, "motor_space", "diverged", "iteration"]  # a column none has: left out
    pd.testing.assert_frame_equal(few, whole[held])


def test_a_damaged_chunk_read_for_a_few_columns_is_named(trial, tmp_path):
    damaged = tmp_path / "trial"
    shutil.copytree(trial, damaged)
    chunk = sorted((damaged / LOG_DIR / "iterations").iterdir())[1]
    chunk.write_bytes(chunk.read_bytes()[:200])
    with pytest.raises(storage.CorruptFileError, match=f"{chunk.name} is damaged or truncated"):
        read_log(damaged, columns=["iteration"])


def test_every_row_names_its_trial_seed_backend_and_voice(trial):
    for kind in ("iterations", "words"):
        log = pd.read_parquet(trial / LOG_DIR / kind)
        assert list(log.columns[:4]) == list(SOURCE_COLUMNS)
        assert set(log["trial"]) == {"kinematic-seed2"} and set(log["seed"]) == {2}
        assert set(log["backend"]) == {"kinematic"} and set(log["voice"]) == {"vtl"}


def test_goals_outcomes_and_interests_are_those_the_learner_used(trial):
    log = read_log(trial)
    assert all(log[c].dtype == np.float32 for c in LEARNER_COLUMNS)
    bootstrap = log["model"] == -1
    assert bootstrap.sum() == 10  # random motor babbling: no goal, no outcome
    assert log.loc[bootstrap, [*GOAL_COLUMNS, *REACHED_COLUMNS]].isna().all().all()
    chosen = log[~bootstrap]
    assert chosen[[*GOAL_COLUMNS, *REACHED_COLUMNS]].notna().all().all()
    assert log[list(INTEREST_COLUMNS)].notna().all().all()
    # Each row's interests are the learning progress (learner/interest.py) of the competences
    # -|goal - reached| logged before it: the interest the row's model was chosen from.
    window = learner_preset("project").progress_window
    goals = log[list(GOAL_COLUMNS)].to_numpy(np.float64)
    reached = log[list(REACHED_COLUMNS)].to_numpy(np.float64)
    competence = -np.linalg.norm(goals - reached, axis=1)
    history: dict[int, list[float]] = {k: [] for k in range(len(INTEREST_COLUMNS))}
    for row in range(len(log)):
        for k, column in enumerate(INTEREST_COLUMNS):
            values = history[k]
            half = min(window, len(values) // 2)
            expected = (
                abs(np.mean(values[len(values) - half :]) - np.mean(values[-2 * half : -half]))
                if half
                else 0.0
            )
            assert log[column].iloc[row] == pytest.approx(expected, abs=1e-5), (row, k)
        model = int(log["model"].iloc[row])
        if model >= 0:
            history[model].append(competence[row])
    assert (log[list(INTEREST_COLUMNS)] > 0).any().sum() >= 2  # progress was made, and logged


def test_a_random_babbling_trial_logs_its_interests_too(tmp_path):
    out = tmp_path / "random"
    run_trial(out, _settings(30, babbling="random"), progress=False)
    log = read_log(out)
    assert (log[list(INTEREST_COLUMNS)].iloc[-1] > 0).any()


def test_read_batch_logs_reads_every_trial_of_a_batch(tmp_path, trial):
    batch = tmp_path / "batch"
    shutil.copytree(trial, batch / trial.name)
    run_trial(batch / "physical-seed5", _settings(30, seed=5, grasp="physical"), progress=False)
    (batch / "notes").mkdir()  # not a trial: left out
    log = read_batch_logs(batch, "iterations")
    assert log.groupby("trial").size().to_dict() == {"kinematic-seed2": 120, "physical-seed5": 30}
    assert log.groupby("trial")["seed"].first().to_dict() == {
        "kinematic-seed2": 2,
        "physical-seed5": 5,
    }
    assert set(log.groupby("backend").size().index) == {"kinematic", "physical"}
    words = read_batch_logs(batch, "words")  # the physical trial has no words row yet
    assert list(words["trial"]) == ["kinematic-seed2"]
    with pytest.raises(ValueError, match="no trial directories"):
        read_batch_logs(batch / "notes")
    with pytest.raises(ValueError, match="unknown log kind"):
        read_log(trial, "iteration")


# Trials of the old layout -----------------------------------------------------------------


def _to_old_layout(trial_dir) -> None:
    """A trial as it was written before the kinds had folders: its chunks side by side in
    log/ under their old names, without the columns added since, and no README."""
    log = trial_dir / LOG_DIR
    for kind in ("iterations", "words"):
        for chunk in sorted((log / kind).glob("chunk-*.parquet")):
            start = chunk.name.removeprefix("chunk-")
            table = storage.read_table(chunk).drop(columns=list(SOURCE_COLUMNS))
            table = table.drop(columns=[c for c in LEARNER_COLUMNS if c in table.columns])
            storage.write_table(log / f"{kind}-{start}", table)
            chunk.unlink()
        if (log / kind).exists():
            (log / kind).rmdir()
    (log / LOG_README_FILE).unlink()
    as_before_manifests(trial_dir)  # which came after the folders


@pytest.fixture
def old_trial(tmp_path):
    """A finished 120-iteration trial in the old layout, and its twin in the new one."""
    new = tmp_path / "new" / "trial"
    run_trial(new, _settings(120), progress=False)
    old = tmp_path / "old" / "trial"
    shutil.copytree(new, old)
    _to_old_layout(old)
    assert sorted(p.name for p in (old / LOG_DIR).iterdir()) == [
        "iterations-00000000.parquet",
        "iterations-00000040.parquet",
        "iterations-00000080.parquet",
        "words-00000080.parquet",
    ]
    return old, new


def test_an_old_layout_trial_is_read_checked_and_evaluated(old_trial):
    old, new = old_trial
    # The source from config.json; the learner's columns, which it did not log, missing.
    expected = logs_of(new)
    expected[list(LEARNER_COLUMNS)] = np.float32("nan")
    pd.testing.assert_frame_equal(logs_of(old), expected)
    pd.testing.assert_frame_equal(logs_of(old, "words"), logs_of(new, "words"))
    check_logs(old, 120, trial_identity(open_for_reading(old).config()))
    evaluate_trial(old, EvaluationSettings(n_placements=1))
    assert is_complete(old)
    batch = old.parent.parent / "batch"  # reported as a batch's trial
    shutil.copytree(old, batch / "kinematic-seed2")
    results = collect(batch)
    assert results.trials["diverged"].tolist() == [0]
    assert set(results.curves["metric"]) >= {"tool_use", "best_distance_names"}


def test_an_old_layout_trial_resumes_into_the_folders(old_trial, tmp_path):
    old, _ = old_trial
    notices: list[str] = []
    run_trial(old, _settings(160), resume=True, progress=False, notify=notices.append)
    assert any("moved 4 log chunk(s) of the old layout" in n for n in notices)
    assert sorted(p.name for p in (old / LOG_DIR).iterdir()) == [
        LOG_README_FILE,
        "iterations",
        "words",
    ]
    whole = tmp_path / "whole" / "trial"
    run_trial(whole, _settings(160), progress=False)
    # The folder reads as one table: the old rows gained their source, and NaN where the
    # learner's columns were not logged; everything else is the uninterrupted run's.
    moved = pd.read_parquet(old / LOG_DIR / "iterations")
    expected = read_log(whole)
    expected.loc[expected["iteration"] < 120, list(LEARNER_COLUMNS)] = np.nan
    pd.testing.assert_frame_equal(moved.drop(columns="trial"), expected.drop(columns="trial"))
    pd.testing.assert_frame_equal(logs_of(old, "words"), logs_of(whole, "words"))


def test_a_resume_killed_mid_move_is_finished_by_the_next(old_trial):
    from experiments.trial_dir.old_logs import move_old_chunks

    old, new = old_trial
    config = storage.read_json(old / "config.json")
    first = old / LOG_DIR / "iterations-00000000.parquet"
    # Killed after the first chunk gained its columns, before its rename: the chunk is whole
    # in the old layout, and read as before.
    table = storage.read_table(first)
    table.insert(0, "trial", "trial")
    storage.write_table(first, table)
    check_logs(old, 120, trial_identity(open_for_reading(old).config()))
    moved, _ = move_old_chunks(old, source_of(old, config), listed_chunks(old))
    assert moved == 4
    assert not list((old / LOG_DIR).glob("*.parquet"))
    check_logs(old, 120, trial_identity(open_for_reading(old).config()))
    assert read_log(old)["trial"].eq("trial").all()


def test_a_chunk_in_both_layouts_is_named_and_nothing_is_changed(trial, tmp_path):
    out = tmp_path / "trial"
    shutil.copytree(trial, out)
    shutil.copy(
        out / LOG_DIR / "iterations" / "chunk-00000040.parquet",
        out / LOG_DIR / "iterations-00000040.parquet",
    )
    with pytest.raises(TrialError, match="both hold the iterations from iteration 40"):
        check_logs(out, 120, trial_identity(open_for_reading(out).config()))
    with pytest.raises(DuplicateChunkError):
        read_log(out)
    with pytest.raises(TrialError, match="both hold"):
        run_trial(out, _settings(160), resume=True, progress=False)
    assert (out / LOG_DIR / "iterations-00000040.parquet").exists()
