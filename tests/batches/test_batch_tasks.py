"""A batch's tasks on a cluster in this process: a trial whose failure a retry would
repeat fails once, in the batch's one line, without Dask's traceback; and a stderr that nobody
reads holds up the bar, never the scheduler, so the trials go on."""

from __future__ import annotations

import io
import logging
import sys
import threading
import time
from concurrent.futures import ThreadPoolExecutor

import pytest

from experiments.batches import runner
from experiments.batches.runner import TrialFailed, is_complete, run_and_evaluate, run_batch
from experiments.batches.spec import BatchError, BatchSpec
from experiments.trial_dir.layout import LOG_DIR

SPEC = BatchSpec(
    grasps=("kinematic",), seeds=(0, 1, 2), iterations=10, checkpoint_every=10, eval_placements=1
)


@pytest.fixture(scope="module")
def client():
    """A batch's own cluster, in this process: its scheduler on the client's event loop."""
    from distributed import Client, LocalCluster

    logging.getLogger("distributed").setLevel(logging.WARNING)
    with (
        LocalCluster(
            n_workers=1, threads_per_worker=1, processes=False, dashboard_address=None
        ) as cluster,
        Client(cluster) as c,
    ):
        yield c


class _Said(logging.Handler):
    """What distributed logs (its loggers do not all propagate to pytest's)."""

    def __init__(self) -> None:
        super().__init__(logging.WARNING)
        self.lines: list[str] = []

    def emit(self, record: logging.LogRecord) -> None:
        self.lines.append(record.getMessage())


def test_a_damaged_trial_fails_once_in_one_line_without_dask_s_traceback(
    tmp_path, client, monkeypatch
):
    spec = BatchSpec(
        grasps=("kinematic",), seeds=(0,), iterations=20, checkpoint_every=10, eval_placements=1
    )
    name = spec.trials()[0][0]
    run_batch(spec, tmp_path, client=client, progress=False)
    chunks = sorted((tmp_path / name / LOG_DIR / "iterations").iterdir())
    chunks[0].unlink()  # a lost log chunk: no rerun can bring it back
    runs: list[str] = []
    original = runner.run_trial

    def counted(*args, **kwargs):
        runs.append(str(args[0]))
        return original(*args, **kwargs)

    monkeypatch.setattr(runner, "run_trial", counted)
    said = _Said()
    logging.getLogger("distributed").addHandler(said)
    try:
        with pytest.raises(BatchError) as caught:
            run_batch(spec, tmp_path, client=client, progress=False)
    finally:
        logging.getLogger("distributed").removeHandler(said)
    message = str(caught.value)
    assert message.startswith(f"1 trial(s) failed: {name} (TrialError: ") and "\n" not in message
    assert str(chunks[0].name) in message
    assert len(runs) == 1  # not retried: a retry finds the same damage
    assert not [line for line in said.lines if "Compute Failed" in line], said.lines


def test_a_task_returns_a_failure_a_retry_would_repeat(tmp_path):
    settings = SPEC.trials()[0][1]
    (tmp_path / "config.json").write_text("{")  # a damaged trial directory
    failed = run_and_evaluate(str(tmp_path), settings, 1)
    assert isinstance(failed, TrialFailed)
    assert failed.error.startswith("CorruptFileError: ") and "config.json" in failed.error


class _Unread(io.TextIOBase):
    """A stderr whose reader is away (a pipe full): every write waits until let through."""

    def __init__(self) -> None:
        self.through = threading.Event()
        self.text: list[str] = []

    def write(self, text: str) -> int:
        self.through.wait(120)
        self.text.append(text)
        return len(text)

    def isatty(self) -> bool:
        return False


def test_a_stderr_nobody_reads_holds_up_the_bar_not_the_trials(tmp_path, client, monkeypatch):
    unread = _Unread()
    monkeypatch.setattr(sys, "stderr", unread)
    names = [name for name, _ in SPEC.trials()]
    with ThreadPoolExecutor(1) as pool:
        batch = pool.submit(run_batch, SPEC, tmp_path, client=client, progress=True)
        try:
            for _ in range(1200):  # every 50 ms, up to a minute: no clock is read
                if all(is_complete(tmp_path / name) for name in names) or batch.done():
                    break
                time.sleep(0.05)
            complete = [name for name in names if is_complete(tmp_path / name)]
        finally:
            unread.through.set()
        results = batch.result(timeout=120)
    # Every trial ran while nothing could be shown (the scheduler was never held up).
    assert complete == names
    assert sorted(results) == names
    shown = "".join(unread.text)
    assert "batch: Dask dashboard: " in shown and "30/30" in shown
    assert "done 3, failed 0, running 0" in shown
