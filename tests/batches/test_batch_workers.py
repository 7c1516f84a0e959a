"""A batch on a cluster the user started: every worker is checked before it runs a trial (the
project importable at the submitter's version, the batch directory seen at the same path), in
one line naming the unfit worker, with nothing written; no worker is one line too; the trial
lock names host and pid; the retries are a setting."""

from __future__ import annotations

import fcntl
import logging
import os
import shutil
import socket
import subprocess
import sys
from pathlib import Path

import pytest

from experiments.batches import scheduler as scheduler_module
from experiments.batches import worker_check, workers
from experiments.batches.runner import run_batch
from experiments.batches.spec import BatchError, BatchSpec
from experiments.trial_dir.lock import DirectoryLock, DirectoryLocked

REPO = Path(__file__).resolve().parents[2]
TINY = BatchSpec(grasps=("kinematic",), seeds=(0,), iterations=10, checkpoint_every=10)
# How long a refused batch may take at most here (s): a hang is what these tests catch.
BATCH_LIMIT_S = 120
# How long a started worker has to join the scheduler (s).
JOIN_S = 60


@pytest.fixture
def scheduler():
    """A scheduler without workers, in this process, reachable by TCP; its address."""
    from distributed import LocalCluster

    logging.getLogger("distributed").setLevel(logging.ERROR)
    with LocalCluster(
        n_workers=0, processes=False, protocol="tcp", host="127.0.0.1", dashboard_address=None
    ) as cluster:
        yield cluster.scheduler_address


def _start_worker(address: str, env: dict | None = None, wrap: list[str] | None = None):
    """A `dask worker` process of this environment joined to `address` (its Python given
    `env`'s changes, its command run under `wrap`)."""
    dask = str(Path(sys.executable).with_name("dask"))
    command = [dask, "worker", address, "--nthreads", "1", "--nworkers", "1", "--no-dashboard"]
    worker = subprocess.Popen(
        [*(wrap or []), *command],
        env={**os.environ, **(env or {})},
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
    )
    from distributed import Client

    with Client(address, timeout="10s") as client:
        client.wait_for_workers(1, timeout=JOIN_S)
    return worker


def _batch(address: str, out: Path) -> subprocess.CompletedProcess:
    """`playroom batch` of the smoke profile against `address`, as a user runs it."""
    command = [sys.executable, "-m", "experiments.cli.main", "batch", "--profile", "smoke"]
    return subprocess.run(
        [*command, "--out", str(out), "--scheduler", address, "--quiet"],
        capture_output=True, text=True, timeout=BATCH_LIMIT_S, cwd=REPO,
    )  # fmt: skip


def _stop(worker: subprocess.Popen) -> None:
    worker.terminate()
    try:
        worker.wait(timeout=30)
    except subprocess.TimeoutExpired:
        worker.kill()


def _refused(done: subprocess.CompletedProcess, said: str, out: Path) -> None:
    lines = done.stderr.strip().splitlines()
    assert done.returncode == 2, done.stderr
    assert said in lines[-1] and "nothing was written" in lines[-1], done.stderr
    assert not out.exists() or not any(out.iterdir()), list(out.iterdir())


def test_a_worker_whose_python_finds_another_copy_of_the_project_is_named(scheduler, tmp_path):
    other = tmp_path / "other" / "experiments"
    other.mkdir(parents=True)
    (other / "__init__.py").write_text("raise ImportError('a half-installed copy')\n")
    worker = _start_worker(scheduler, env={"PYTHONPATH": str(other.parent)})
    try:
        done = _batch(scheduler, tmp_path / "out")
    finally:
        _stop(worker)
    _refused(done, "cannot import the project", tmp_path / "out")
    assert "a half-installed copy" in done.stderr and str(other) in done.stderr


def test_a_worker_at_another_commit_is_named(scheduler, tmp_path):
    copy = tmp_path / "copy"
    for package in ("experiments", "sim", "learner", "models"):
        shutil.copytree(
            REPO / package, copy / package, ignore=shutil.ignore_patterns("__pycache__")
        )
    git = ["git", "-C", str(copy), "-c", "user.name=t", "-c", "user.email=t@t"]
    subprocess.run([*git, "init", "-q"], check=True)
    subprocess.run([*git, "add", "-A"], check=True)
    subprocess.run([*git, "commit", "-q", "-m", "another version"], check=True)
    theirs = subprocess.run([*git, "rev-parse", "HEAD"], capture_output=True, text=True).stdout
    worker = _start_worker(scheduler, env={"PYTHONPATH": str(copy)})
    try:
        done = _batch(scheduler, tmp_path / "out")
    finally:
        _stop(worker)
    _refused(done, "runs another version of the project", tmp_path / "out")
    assert f"commit {theirs[:10]}" in done.stderr


def _private_mounts_allowed() -> bool:
    try:
        done = subprocess.run(["unshare", "-m", "true"], capture_output=True, timeout=10)
    except (OSError, subprocess.TimeoutExpired):
        return False
    return done.returncode == 0


@pytest.mark.skipif(not _private_mounts_allowed(), reason="no private mount namespaces here")
def test_a_worker_that_sees_another_directory_at_the_batch_path_is_named(scheduler, tmp_path):
    shared = tmp_path / "shared"
    shared.mkdir()
    # The worker's own empty filesystem mounted over the batch's parent: no shared filesystem.
    private = f'mount -t tmpfs tmpfs {shared} && exec "$@"'
    worker = _start_worker(scheduler, wrap=["unshare", "-m", "sh", "-c", private, "sh"])
    try:
        done = _batch(scheduler, shared / "out")
    finally:
        _stop(worker)
    _refused(done, "does not see the batch directory", shared / "out")


def test_a_worker_reading_another_token_at_the_path_writes_nothing(tmp_path):
    """The check a worker joining late runs before its first trial: another directory at the
    batch's path (its token differs) is refused, and the trial is not begun."""
    out = tmp_path / "out"
    out.mkdir()
    path, _ = workers.write_token(out, "run1")
    expected = {"code": workers.code_expected(), "token_path": str(path), "token": "another"}
    settings = {"grasp": "kinematic", "iterations": 10, "seed": 0, "checkpoint_every": 10}
    result = worker_check.guarded_trial(expected, str(out / "trial"), settings, 100)
    assert "sees another directory at" in result[worker_check.UNFIT]
    assert not (out / "trial").exists()


def test_no_worker_is_one_line_and_nothing_is_written(scheduler, tmp_path):
    from distributed import Client

    with Client(scheduler, timeout="10s") as client, pytest.raises(BatchError) as caught:
        run_batch(TINY, tmp_path / "out", client=client, progress=False, worker_wait_s=1)
    message = str(caught.value)
    assert "no Dask worker joined" in message and "\n" not in message
    assert not (tmp_path / "out").exists()


def test_the_retries_are_the_schedulers_allowed_failures(tmp_path):
    from distributed import Client, LocalCluster

    with (
        LocalCluster(n_workers=1, threads_per_worker=1, processes=False, dashboard_address=None)
        as cluster,
        Client(cluster) as client,
    ):  # fmt: skip
        run_batch(TINY, tmp_path / "out", client=client, progress=False, retries=7)
        assert cluster.scheduler.allowed_failures == 7
    assert not list((tmp_path / "out").glob(".workers-*")), "the run's token is removed"


def test_a_trial_whose_worker_died_too_often_says_what_to_do():
    from distributed.scheduler import KilledWorker

    said = scheduler_module.failure_text(KilledWorker("k", None, 2), retries=2)
    assert "died 3 times" in said and "--retries" in said


def test_a_lost_schedulers_line_says_what_to_restart():
    said = str(scheduler_module.lost_error("tcp://10.0.0.1:8786", 3))
    assert "dask scheduler" in said and "dask worker" in said and "3 trial(s)" in said


def test_the_lock_names_the_host_and_pid_of_its_holder(tmp_path):
    lock = DirectoryLock(tmp_path).acquire()
    try:
        assert lock.path.read_text().split() == [str(os.getpid()), socket.gethostname()]
    finally:
        lock.release()
    # Held by a writer on another machine (its flock taken here on another open file).
    fd = os.open(tmp_path / ".lock", os.O_RDWR)
    try:
        fcntl.flock(fd, fcntl.LOCK_EX)
        os.ftruncate(fd, 0)
        os.pwrite(fd, b"4242 node17\n", 0)
        with pytest.raises(DirectoryLocked, match="pid 4242 on node17"):
            DirectoryLock(tmp_path).acquire()
    finally:
        os.close(fd)


@pytest.mark.slow
def test_a_batch_on_fit_workers_runs(scheduler, tmp_path):
    worker = _start_worker(scheduler)
    try:
        done = _batch(scheduler, tmp_path / "out")
    finally:
        _stop(worker)
    assert done.returncode == 0, done.stderr
    assert (tmp_path / "out" / "batch.json").exists()
    assert not list((tmp_path / "out").glob(".workers-*"))
