"""Ctrl-C (SIGINT) and SIGTERM end `playroom run` and `playroom batch` with one line saying
how to resume, exit codes 130 and 143, the trial's lock released (experiments/faults.py)."""

from __future__ import annotations

import argparse
import errno
import os
import shlex
import signal
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable
from pathlib import Path

import pytest

from experiments.analysis.logs import read_log
from experiments.cli import faults
from experiments.trial_dir import storage
from experiments.trial_dir.layout import CHECKPOINT_FILE
from experiments.trial_dir.lock import DirectoryLock

# -X faulthandler: a run that outlives its signal shows where it was (SIGABRT below).
PLAYROOM = [sys.executable, "-X", "faulthandler", "-m", "experiments.cli.main"]
REPO = Path(__file__).resolve().parents[2]
# The pause between two looks at a trial directory for its next checkpoint (seconds): how
# often the tests look, never how long they wait.
LOOK_EVERY_S = 0.025


def _checkpointed(trial: Path) -> int:
    """The iteration of the trial's newest checkpoint (0 if none can be read yet)."""
    try:
        return storage.read_meta(trial / CHECKPOINT_FILE)["iteration"]
    except (FileNotFoundError, storage.CorruptFileError):
        return 0


def _interruptible() -> None:
    signal.signal(signal.SIGINT, signal.SIG_DFL)


def _wait_for_checkpoint(trial: Path, past: int, ended: Callable[[], bool]) -> bool:
    """Wait until the trial has a checkpoint past iteration `past` (True), or until `ended()`
    says that what writes the trial has stopped without one (False). However long that takes:
    the wait ends on what the trial does, never on a count of looks, which is a clock in
    disguise (a bound of 1200 looks, some 30 s, sent the signal anyway on a machine loaded by
    `make test-slow`, to a trial that had no checkpoint yet)."""
    while _checkpointed(trial) <= past:
        if ended():
            return False
        time.sleep(LOOK_EVERY_S)
    return True


def _stop_after(command: list[str], trial: Path, past: int, signum: int, **popen) -> tuple:
    """Start `command`, send `signum` once the trial has a checkpoint past iteration `past`;
    (exit code, stderr)."""
    # stderr goes to a file, not a pipe: a pipe nobody reads while the test waits would block
    # the command once full.
    with tempfile.TemporaryFile("w+") as stderr:
        # As from a terminal: Ctrl-C interrupts. A pytest-xdist worker ignores SIGINT, and a
        # child inherits that (a process started ignoring SIGINT, as under nohup, is meant to
        # ignore it).
        proc = subprocess.Popen(
            command, stderr=stderr, text=True, cwd=REPO, preexec_fn=_interruptible, **popen
        )
        if not _wait_for_checkpoint(trial, past, lambda: proc.poll() is not None):
            stderr.seek(0)
            raise AssertionError(
                f"ended ({proc.returncode}) before a checkpoint past {past}:\n{stderr.read()}"
            )
        if popen.get("start_new_session"):
            os.killpg(proc.pid, signum)  # as a terminal or a job scheduler signals a whole job
        else:
            proc.send_signal(signum)
        try:
            proc.wait(timeout=60)
        except subprocess.TimeoutExpired:
            proc.send_signal(signal.SIGABRT)
            proc.wait()
            stderr.seek(0)
            raise AssertionError(
                f"still running 60 s after signal {signum}:\n{stderr.read()}"
            ) from None
        stderr.seek(0)
        return proc.returncode, stderr.read()


def _lock_is_free(trial: Path) -> bool:
    lock = DirectoryLock(trial).acquire()
    lock.release()
    return True


@pytest.mark.slow  # over 5 s: make test-slow runs it
def test_sigint_then_sigterm_end_a_run_with_one_line_and_it_resumes(tmp_path):
    out = tmp_path / "trial"
    # The study's 80000 iterations: a longer trial states its estimated costs first.
    args = ["run", "--out", str(out), "--iterations", "80000", "--checkpoint-every", "50"]
    code, err = _stop_after([*PLAYROOM, *args, "--quiet"], out, 0, signal.SIGINT)
    assert code == 130, err
    first = _checkpointed(out)
    line = err.strip()
    assert "\n" not in line and "Traceback" not in line
    assert line.startswith("playroom run: interrupted") and f"iteration {first}" in line
    assert _lock_is_free(out)

    # The command the line gives resumes the trial; SIGTERM stops it the same way.
    resume = shlex.split(line.split("resume with: ")[1])
    assert resume[0] == "playroom" and "--resume" in resume
    code, err = _stop_after([*PLAYROOM, *resume[1:]], out, first, signal.SIGTERM)
    assert code == 143, err
    lines = err.strip().splitlines()
    assert len(lines) == 1 and "interrupted" in lines[0] and "--resume" in lines[0]
    second = _checkpointed(out)
    assert second > first
    assert list(read_log(out)["iteration"]) == list(range(second))  # nothing lost or doubled


@pytest.mark.slow  # over 5 s: make test-slow runs it
def test_sigterm_ends_a_batch_with_one_line_saying_how_to_resume(tmp_path):
    config = tmp_path / "batch.json"
    config.write_text(
        '{"grasps": ["kinematic"], "seeds": [0], "iterations": 100000, '
        '"checkpoint_every": 50, "eval_placements": 1}'
    )
    out = tmp_path / "batch"
    trial = out / "kinematic-random-seed0000"
    command = [*PLAYROOM, "batch", "--config", str(config), "--out", str(out), "--workers", "1"]
    code, err = _stop_after(command, trial, 0, signal.SIGTERM, start_new_session=True)
    assert code == 143, err
    assert "Traceback" not in err and "Warning" not in err
    # The progress bar's lines come first, ended; the last line says how to go on.
    last = err.rstrip("\n").split("\n")[-1]
    assert last.startswith("playroom batch: interrupted")
    assert f"rerun the same command to resume: playroom batch --config {config}" in last
    first = _checkpointed(trial)
    assert first > 0 and _lock_is_free(trial)

    # The command the line gives resumes the trial from its checkpoint.
    again = shlex.split(last.split("rerun the same command to resume: ")[1])
    assert again[0] == "playroom"
    code, err = _stop_after(
        [*PLAYROOM, *again[1:]], trial, first, signal.SIGTERM, start_new_session=True
    )
    assert code == 143, err
    assert err.rstrip("\n").split("\n")[-1] == last
    second = _checkpointed(trial)
    assert second > first and _lock_is_free(trial)
    assert list(read_log(trial)["iteration"]) == list(range(second))  # nothing lost or doubled


# The handler itself, in this process -------------------------------------------------------------
def _ended_by(failure: BaseException, capsys, command: str = "report") -> tuple[int, str]:
    def func(args):
        raise failure

    args = argparse.Namespace(command=command, func=func, out="nowhere")
    code = faults.run_command(args, [command, "x"])
    return code, capsys.readouterr().err


def test_each_way_out_has_its_exit_code_and_one_line(capsys):
    full = storage.WriteError(errno.ENOSPC, os.strerror(errno.ENOSPC), "/x/report.html")
    code, err = _ended_by(full, capsys)
    assert code == 1
    assert err == (
        "playroom report: error: cannot write /x/report.html: no space left on device; "
        "nothing was written\n"
    )
    code, err = _ended_by(KeyboardInterrupt(), capsys)
    assert (code, err) == (130, "playroom report: interrupted; nothing was written\n")
    code, err = _ended_by(faults.Terminated(), capsys, command="say")
    assert (code, err) == (143, "playroom say: interrupted\n")
    code, err = _ended_by(faults.UsageError("bad"), capsys)
    assert (code, err) == (2, "playroom report: error: bad\n")


def test_sigterm_raises_in_the_block_and_the_handlers_are_restored():
    before = signal.getsignal(signal.SIGTERM), signal.getsignal(signal.SIGINT)
    with pytest.raises(faults.Terminated):
        with faults.signals_as_exceptions():
            os.kill(os.getpid(), signal.SIGTERM)
            for _ in range(1000):  # the handler runs at the next bytecode boundaries
                time.sleep(0.001)
    assert (signal.getsignal(signal.SIGTERM), signal.getsignal(signal.SIGINT)) == before


def test_a_stop_raised_inside_a_finalizer_still_stops_the_run(tmp_path, monkeypatch, capsys):
    """Python drops an exception raised in a `__del__` (pyarrow's ParquetWriter has one, run
    after each log chunk): the stop it carried is raised again at the next iteration."""
    from experiments.cli.main import main
    from experiments.trial_dir import writing

    class SignalsWhenCollected:
        def __del__(self) -> None:
            os.kill(os.getpid(), signal.SIGTERM)
            for _ in range(1000):  # the handler runs here, inside the finalizer
                time.sleep(0.0001)

    write_table = writing.storage.write_table

    def write_then_collect(*args, **kwargs):
        write_table(*args, **kwargs)
        SignalsWhenCollected()  # collected at once: the signal arrives in its __del__

    monkeypatch.setattr(writing.storage, "write_table", write_then_collect)
    dropped: list = []  # what Python drops: exceptions raised in finalizers
    monkeypatch.setattr(sys, "unraisablehook", dropped.append)
    out = tmp_path / "trial"
    args = ["run", "--out", str(out), "--iterations", "400", "--checkpoint-every", "50"]
    code = main([*args, "--quiet"])
    err = capsys.readouterr().err
    assert [type(d.exc_value).__name__ for d in dropped] == ["Terminated"]  # the first raise
    assert code == 143, err
    assert err.strip().splitlines()[-1].startswith("playroom run: interrupted")
    assert _checkpointed(out) == 50  # stopped in the chunk after the first one


@pytest.mark.slow  # a cluster of its own: over 5 s
def test_a_batch_waiting_for_its_trials_hears_a_stop_python_dropped(tmp_path):
    """A stop whose exception Python dropped (in a finalizer) while the batch waits for its
    trials stops the batch then, not when the next trial ends."""
    import threading

    from experiments.batches.runner import run_batch
    from experiments.batches.spec import BatchSpec
    from experiments.run import stop_requests

    spec = BatchSpec(grasps=("kinematic",), seeds=(0,), iterations=100000, checkpoint_every=50)
    out = tmp_path / "batch"
    trial = out / "kinematic-random-seed0000"

    batch_ended = threading.Event()

    def stop_once_the_trial_runs() -> None:
        if not _wait_for_checkpoint(trial, 0, batch_ended.is_set):
            return  # the batch ended by itself: pytest.raises below says so
        try:  # the handler records the request; its exception is lost in this thread
            stop_requests.handle(signal.SIGTERM, None)
        except stop_requests.Terminated:
            pass

    stopper = threading.Thread(target=stop_once_the_trial_runs)
    stopper.start()
    try:
        with pytest.raises(stop_requests.Terminated):
            run_batch(spec, out, n_workers=1, progress=False)
    finally:
        batch_ended.set()
        stopper.join()
        stop_requests.clear()
    assert 0 < _checkpointed(trial) < 100000
    assert _lock_is_free(trial)
