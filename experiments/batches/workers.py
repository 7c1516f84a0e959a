"""The submitter's side of a batch's workers: waiting for some, checking every one before it
runs a trial (experiments/batches/worker_check.py, which runs on them), and the settings the
scheduler gives a trial whose worker dies.

A cluster the user started is not the submitter's machine: a worker may run another Python
(no project, or another copy of it found first), another version of the project, or see
another directory at the batch's path (no shared filesystem). Unchecked, the first hung the
batch, the second mixed results of two versions into one batch, the third wrote trials where
the batch could not read them and reported success. Each is now one line naming the worker
and what to do, before anything is written; a worker joining later is checked by its first
task, before it writes anything.
"""

from __future__ import annotations

import os
import secrets
import time
from collections.abc import Callable
from pathlib import Path

import cloudpickle  # type: ignore[import-untyped]

from experiments.batch_files import WORKER_TOKEN_FILE
from experiments.batches import worker_check
from experiments.batches.cluster_settings import NO_WORKER_NOTICE_S, WORKER_COUNT_EVERY_S
from experiments.batches.spec import BatchError
from experiments.trial_dir import provenance

# Sent by value: the check must run on a worker that cannot import the project.
cloudpickle.register_pickle_by_value(worker_check)


def code_expected() -> dict:
    """What every worker's code must be: the submitter's commit and its versions of Python and
    of the libraries that change a trial's bits (experiments/trial_dir/provenance.py COMPUTING)."""
    record = provenance.machine_record()
    versions = record["versions"]
    names = ("python", *provenance.COMPUTING)
    return {"source": record["source"], "versions": {n: versions.get(n) for n in names}}


def write_token(out: Path, run: str) -> tuple[Path, str]:
    """(path, token): a new token written into the batch directory for the workers to read."""
    path = out / WORKER_TOKEN_FILE.format(run)
    token = secrets.token_hex(16)
    path.write_text(token, encoding="utf-8")
    return path, token


def remove_token(path: Path) -> None:
    """The run's token gone (a run killed before it leaves one: harmless, named by run)."""
    try:
        path.unlink()
    except OSError:
        pass


def worker_count(client) -> int:
    return len(client.scheduler_info(n_workers=-1).get("workers", {}))


def wait_for_workers(client, address: str | None, wait_s: float) -> None:
    """Return once the scheduler has a worker; BatchError (one line) after `wait_s` seconds
    without one."""
    try:
        client.wait_for_workers(1, timeout=wait_s)
    except TimeoutError:
        raise BatchError(
            f"no Dask worker joined the scheduler at {address} within {wait_s:g} s: start "
            f"workers from the project's environment (`dask worker {address}`, or `playroom "
            "cluster`: docs/usage.md), or wait longer with --worker-wait SECONDS; nothing was "
            "written"
        ) from None


def check_workers(client, expected: dict) -> None:
    """BatchError naming the first unfit worker of the scheduler's (and how many more there
    are), each checked on itself (`worker_check.worker_problem`)."""
    found = client.run(worker_check.worker_problem, expected, on_error="return")
    problems = []
    for address, problem in sorted(found.items()):
        if isinstance(problem, BaseException):  # the check itself failed there
            problem = f"worker {address} could not be checked ({type(problem).__name__}: {problem})"
        if problem is not None:
            problems.append(str(problem))
    if problems:
        more = f" (and {len(problems) - 1} more unfit worker(s))" if len(problems) > 1 else ""
        raise BatchError(f"{problems[0]}{more}; nothing was written")


def allow_failures(client, retries: int) -> None:
    """Let a trial's worker die `retries` times before the scheduler gives the trial up
    (KilledWorker). A scheduler the user started is told too: the setting is its own, for
    every client (docs/usage.md)."""
    client.run_on_scheduler(worker_check.set_allowed_failures, retries)


class WorkerWatch:
    """Says once, through `say`, when the running batch has had no worker for
    NO_WORKER_NOTICE_S (their jobs ended, their machines lost): the trials wait for one."""

    def __init__(self, client, address: str | None, say: Callable[[str], None]) -> None:
        self.client, self.address, self.say = client, address, say
        self._since: float | None = None
        self._counted = 0.0
        self._said = False

    def look(self) -> None:
        now = time.monotonic()
        if now - self._counted < WORKER_COUNT_EVERY_S:
            return
        self._counted = now
        if worker_count(self.client):
            self._since, self._said = None, False
            return
        self._since = self._since or now
        if not self._said and now - self._since >= NO_WORKER_NOTICE_S:
            self._said = True
            self.say(
                f"no Dask worker at {self.address} for {NO_WORKER_NOTICE_S} s: the trials "
                "wait for one (start workers, or stop with Ctrl-C: they resume from their "
                "checkpoints)"
            )


def created(out: Path) -> bool:
    """Make the batch directory if it is missing; whether it was made now."""
    if out.is_dir():
        return False
    out.mkdir(parents=True, exist_ok=True)
    return True


def undo_created(out: Path, made: bool) -> None:
    """A batch directory made now and left empty (its workers refused) removed again."""
    if made:
        try:
            os.rmdir(out)
        except OSError:
            pass
