"""A trial directory has one writer, can be extended, and survives a damaged checkpoint."""

from __future__ import annotations

import signal
import subprocess
import sys
import threading

import pytest
from trial_states import same_state

from experiments.batches.runner import run_and_evaluate
from experiments.measure.evaluation import EvaluationSettings
from experiments.measure.trial_evaluation import evaluate_trial
from experiments.run.settings import TrialSettings
from experiments.run.trial import run_trial
from experiments.trial_dir import storage
from experiments.trial_dir.errors import TrialError, TrialLocked
from experiments.trial_dir.layout import (
    CHECKPOINT_FILE,
    CONFIG_FILE,
    DAMAGED_CHECKPOINT_FILE,
    EVAL_FILE,
    LOCK_FILE,
    PREVIOUS_CHECKPOINT_FILE,
)
from experiments.trial_dir.lock import DirectoryLock

PLAYROOM = [sys.executable, "-m", "experiments.cli.main"]
HOLD_LOCK = (
    "import sys, time; from experiments.trial_dir.lock import DirectoryLock; "
    "DirectoryLock(sys.argv[1]).acquire(); print('held', flush=True); time.sleep(600)"
)


def _run_cli(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run([*PLAYROOM, *args], capture_output=True, text=True)


@pytest.fixture
def lock_holder(tmp_path):
    """Another process holding the lock of tmp_path / 'trial'; yields (directory, process)."""
    directory = tmp_path / "trial"
    proc = subprocess.Popen(
        [sys.executable, "-c", HOLD_LOCK, str(directory)], stdout=subprocess.PIPE, text=True
    )
    assert proc.stdout.readline().strip() == "held"
    yield directory, proc
    proc.kill()
    proc.wait()


# One writer ---------------------------------------------------------------------------------
def test_a_second_writer_gets_one_line_with_the_holders_pid_and_touches_nothing(lock_holder):
    directory, holder = lock_holder
    before = sorted(p.name for p in directory.iterdir())
    result = _run_cli("run", "--iterations", "20", "--out", str(directory), "--quiet")
    assert result.returncode == 2
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1 and f"pid {holder.pid}" in lines[0] and str(directory) in lines[0]
    assert sorted(p.name for p in directory.iterdir()) == before
    with pytest.raises(TrialLocked):
        run_trial(directory, TrialSettings(iterations=20), progress=False)


def test_the_lock_dies_with_its_holder_even_on_kill_9(lock_holder):
    directory, holder = lock_holder
    holder.send_signal(signal.SIGKILL)
    holder.wait()
    trial = run_trial(directory, TrialSettings(iterations=20), progress=False)
    assert trial.iteration == 20
    # Released when the run ends: the same process (a batch worker) can take it again.
    DirectoryLock(directory).acquire().release()


def test_a_batch_task_waits_for_the_other_writer_then_completes(lock_holder):
    directory, holder = lock_holder
    results = []
    task = threading.Thread(
        target=lambda: results.append(
            run_and_evaluate(str(directory), TrialSettings(iterations=20), eval_placements=1)
        )
    )
    task.start()
    task.join(timeout=2.0)  # long enough for the task to run, had it not waited
    assert task.is_alive() and not (directory / CONFIG_FILE).exists()  # waiting, writing nothing
    holder.kill()
    task.join()
    assert results and results[0]["evaluated_at_iteration"] == 20


def test_evaluation_is_refused_while_another_process_writes(lock_holder, tmp_path):
    directory, holder = lock_holder
    holder.kill()
    holder.wait()
    run_trial(directory, TrialSettings(iterations=20), progress=False)
    proc = subprocess.Popen(
        [sys.executable, "-c", HOLD_LOCK, str(directory)], stdout=subprocess.PIPE, text=True
    )
    try:
        assert proc.stdout.readline().strip() == "held"
        with pytest.raises(TrialLocked, match=f"pid {proc.pid}"):
            evaluate_trial(directory, EvaluationSettings(n_placements=1))
        assert not (directory / EVAL_FILE).exists()
    finally:
        proc.kill()
        proc.wait()


# Extending a trial --------------------------------------------------------------------------
def test_resume_with_more_iterations_equals_the_longer_run_from_the_start(tmp_path):
    short, whole = tmp_path / "short", tmp_path / "whole"
    run_trial(short, TrialSettings(iterations=150, seed=2, checkpoint_every=100), progress=False)
    evaluate_trial(short, EvaluationSettings(n_placements=1))
    notices: list[str] = []
    longer = TrialSettings(iterations=250, seed=2, checkpoint_every=100)
    run_trial(short, longer, resume=True, progress=False, notify=notices.append)
    run_trial(whole, longer, progress=False)
    same_state(short, whole)
    assert storage.read_json(short / CONFIG_FILE) == storage.read_json(whole / CONFIG_FILE)
    # The shorter run's evaluation is moved aside, not mixed with the longer trial.
    assert not (short / EVAL_FILE).exists()
    stale = storage.read_json(short / "stale-at-00000150" / EVAL_FILE)
    assert stale["evaluated_at_iteration"] == 150
    assert len(notices) == 1 and "150 to 250" in notices[0]


def test_resume_cannot_shorten_a_trial_or_change_another_setting(tmp_path):
    out = tmp_path / "t"
    run_trial(out, TrialSettings(iterations=60, seed=1, checkpoint_every=30), progress=False)
    before = (out / CHECKPOINT_FILE).read_bytes()
    with pytest.raises(TrialError, match="shorten"):
        run_trial(out, TrialSettings(iterations=40, seed=1, checkpoint_every=30), resume=True)
    with pytest.raises(TrialError, match="trial.checkpoint_every: 30 != 20"):
        run_trial(out, TrialSettings(iterations=90, seed=1, checkpoint_every=20), resume=True)
    assert (out / CHECKPOINT_FILE).read_bytes() == before
    assert storage.read_json(out / CONFIG_FILE)["trial"]["iterations"] == 60


# Damaged checkpoints ------------------------------------------------------------------------
@pytest.fixture(scope="module")
def whole_run(tmp_path_factory):
    """An uninterrupted 90-iteration trial, checkpointed every 30."""
    out = tmp_path_factory.mktemp("whole") / "t"
    run_trial(out, TrialSettings(iterations=90, seed=6, checkpoint_every=30), progress=False)
    return out


def _trial_with_last_checkpoint_lost(tmp_path, damage) -> tuple:
    """A copy of the trial killed just after its checkpoint at 60, whose newest checkpoint is
    then damaged by `damage(path)`."""
    out = tmp_path / "t"
    run_trial(out, TrialSettings(iterations=60, seed=6, checkpoint_every=30), progress=False)
    damage(out / CHECKPOINT_FILE)
    args = ["run", "--iterations", "90", "--seed", "6", "--checkpoint-every", "30", "--quiet"]
    return out, args


@pytest.mark.slow  # over 5 s: make test-slow runs it
def test_a_truncated_newest_checkpoint_falls_back_to_the_previous_one(tmp_path, whole_run):
    def truncate(path):
        path.write_bytes(path.read_bytes()[:300])

    out, args = _trial_with_last_checkpoint_lost(tmp_path, truncate)
    damaged = (out / CHECKPOINT_FILE).read_bytes()
    # Evaluation does not guess: it names the damage and the way out.
    result = _run_cli("eval", str(out), "--quiet")
    assert result.returncode == 2 and "--resume" in result.stderr
    result = _run_cli(*args, "--out", str(out), "--resume")
    assert result.returncode == 0, result.stderr
    notice = [line for line in result.stderr.splitlines() if "previous checkpoint" in line]
    assert len(notice) == 1 and "iteration 30" in notice[0]
    assert (out / DAMAGED_CHECKPOINT_FILE).read_bytes() == damaged
    same_state(out, whole_run)


def test_a_newest_checkpoint_lost_while_being_replaced_falls_back(tmp_path, whole_run):
    out, args = _trial_with_last_checkpoint_lost(tmp_path, lambda path: path.unlink())
    assert (out / PREVIOUS_CHECKPOINT_FILE).exists()
    result = _run_cli(*args, "--out", str(out), "--resume")
    assert result.returncode == 0, result.stderr
    assert "previous checkpoint" in result.stderr
    same_state(out, whole_run)


def test_both_checkpoints_damaged_is_one_line_and_destroys_nothing(tmp_path):
    def truncate(path):
        path.write_bytes(path.read_bytes()[:300])

    out, args = _trial_with_last_checkpoint_lost(tmp_path, truncate)
    truncate(out / PREVIOUS_CHECKPOINT_FILE)

    def contents() -> dict:  # the lock file names its last holder: not trial data
        return {p: p.read_bytes() for p in out.rglob("*") if p.is_file() and p.name != LOCK_FILE}

    before = contents()
    result = _run_cli(*args, "--out", str(out), "--resume")
    assert result.returncode == 2 and "damaged or truncated" in result.stderr
    assert len(result.stderr.strip().splitlines()) == 1
    assert contents() == before
