"""What a batch shows while it runs: one bar of the iterations done across its trials, which
advances within a trial, with the running trials named beside it, and the Dask dashboard's link.

Each batch task tells the client the iteration its trial reached (about once a second,
through the worker's event log: `distributed`'s `log_event`, one topic per batch
run); the client's subscription moves the bar. A task that runs again (a lost worker) reports
from where its trial resumes.

Only a thread of the bar's own writes to the terminal. Reports arrive on the client's event
loop, which in a batch's own cluster also runs the scheduler: a bar drawn there, or a lock
taken there that the batch's loop held while drawing, froze the scheduler whenever stderr
blocked (a pipe not read for a while fills after about 140 trials of bar): workers idle,
nothing started, the bar stuck on a trial long finished. A stderr that blocks now
holds up the bar alone.

Reports and ends travel apart: a report reaches the client through the scheduler's event log, a
task's end through its future, seen by the batch's loop up to a poll later. So a report may
arrive after its trial's end, and the next trial of a worker may report before the previous
one's end is seen. The trials running are therefore the last one each task thread reported
(one task at a time runs on a thread), never a trial whose end was seen: a set of names added
on report and removed on end named ended trials as running for good, and counted 4 trials
running on 2 workers.
"""

from __future__ import annotations

import math
import sys
import threading
import time
from collections.abc import Callable

from tqdm import tqdm

# Iterations between two looks at the clock of a running trial, and the least time between two
# of its reports: each report wakes the worker's and the scheduler's event loops (reports every
# 100 iterations slowed kinematic trials by 8%).
REPORT_EVERY = 100
REPORT_INTERVAL_S = 1.0
# Running trials named in the bar's postfix; more are counted.
NAMED_RUNNING = 3
# The least time between two drawings of the bar (s), as tqdm's own default.
DRAW_INTERVAL_S = 0.1


class _Bar(tqdm):
    """tqdm with a lock of its own: a batch task sets tqdm's shared lock when it starts
    (experiments/batches/runner.py), which on a cluster of threads in this process would swap
    the lock under a bar drawing ("cannot release un-acquired lock")."""

    _lock = threading.RLock()


def dashboard_link(client) -> str | None:
    """The Dask dashboard's address as the client sees it (a local cluster's, or a remote
    scheduler's), None where the scheduler serves none."""
    try:
        link = client.dashboard_link
    except Exception:  # a scheduler without a dashboard service: distributed's KeyError & co
        return None
    return link or None


def reporter(
    topic: str | None, name: str, min_interval_s: float = REPORT_INTERVAL_S
) -> Callable[[int], None] | None:
    """From inside a batch task: the callable that reports `name`'s iteration under `topic`,
    its start at once, later iterations at most once every `min_interval_s`; None outside a
    worker (a task called directly has no client to tell)."""
    if topic is None:
        return None
    from distributed import get_worker

    try:
        worker = get_worker()
    except ValueError:
        return None
    last = -math.inf
    # Where the trial runs: the worker's task thread, which runs one task at a time.
    where = f"{worker.address}/{threading.get_ident()}"

    def report(iteration: int) -> None:
        nonlocal last
        now = time.monotonic()
        if now - last >= min_interval_s:
            last = now
            worker.log_event(topic, {"trial": name, "iteration": iteration, "thread": where})

    return report


class BatchProgress:
    """The bar of a batch: `total` iterations over the trials to run (name -> iterations), and
    the lines said while they run (`say`), drawn by a thread of its own (module docstring):
    every other method only records, and never waits on the terminal."""

    def __init__(self, trials: dict[str, int], enabled: bool) -> None:
        self._lock = threading.Lock()  # held only to read or change what is shown
        self._reached = dict.fromkeys(trials, 0)
        self._total = trials
        self._running: dict[str, str] = {}  # task thread -> the trial it last reported
        self._ended: set[str] = set()
        self._counts = {"done": 0, "failed": 0}
        self._lines: list[str] = []
        self._closing = False
        self._changed = threading.Event()
        self._drawer = threading.Thread(
            target=self._draw, args=(enabled,), name="batch-progress", daemon=True
        )
        self._drawer.start()

    def reached(self, name: str, iteration: int, thread: str | None = None) -> None:
        """A trial reports the iteration it reached, from the task thread `thread` that runs
        it (None: a thread of its own)."""
        with self._lock:
            if name not in self._reached or name in self._ended:  # a report after its end
                return
            self._running[name if thread is None else thread] = name
            self._reached[name] = min(iteration, self._total[name])
        self._changed.set()

    def ended(self, name: str, failed: bool) -> None:
        """A trial's task ended (run and evaluated, or failed)."""
        with self._lock:
            self._ended.add(name)
            self._running = {t: n for t, n in self._running.items() if n != name}
            self._counts["failed" if failed else "done"] += 1
            if not failed:  # its iterations count even where a report was missed
                self._reached[name] = self._total[name]
        self._changed.set()

    def say(self, line: str) -> None:
        """Print `line` on stderr above the bar."""
        with self._lock:
            self._lines.append(line)
        self._changed.set()

    def listen(self, client, topic: str) -> None:
        """Move the bar with every report sent under `topic`."""

        def on_event(event: tuple) -> None:
            message = event[1]
            if isinstance(message, dict):
                thread = message.get("thread")
                self.reached(
                    str(message.get("trial")),
                    int(message.get("iteration", 0)),
                    None if thread is None else str(thread),
                )

        client.subscribe_topic(topic, on_event)

    def postfix(self) -> str:
        """What the bar shows beside its count: trials done, failed and running."""
        with self._lock:
            return self._postfix()

    def _postfix(self) -> str:
        running = sorted(set(self._running.values()))
        named = ", ".join(running[:NAMED_RUNNING])
        more = len(running) - NAMED_RUNNING
        return (
            f"done {self._counts['done']}, failed {self._counts['failed']}, running "
            f"{len(running)}"
            + (f": {named}" if running else "")
            + (f" +{more}" if more > 0 else "")
        )

    def iterations_done(self) -> int:
        """Iterations done across the trials, as the bar shows them."""
        with self._lock:
            return sum(self._reached.values())

    def running(self) -> list[str]:
        """The trials running: the last one each task thread reported, unless it ended."""
        with self._lock:
            return sorted(set(self._running.values()))

    def close(self) -> None:
        """Draw the last state and every line said, then end the bar (waits for stderr)."""
        with self._lock:
            self._closing = True
        self._changed.set()
        self._drawer.join()

    def _draw(self, enabled: bool) -> None:
        """The drawing thread: what changed, at most every DRAW_INTERVAL_S, until closed."""
        try:
            bar = _Bar(
                total=sum(self._total.values()), disable=not enabled, desc="batch", unit="it",
                dynamic_ncols=True, file=sys.stderr,
            )  # fmt: skip
            while True:
                self._changed.wait()
                self._changed.clear()
                with self._lock:
                    lines, self._lines = self._lines, []
                    done, postfix = sum(self._reached.values()), self._postfix()
                    closing = self._closing
                for line in lines:
                    _Bar.write(line, file=sys.stderr)
                bar.set_postfix_str(postfix, refresh=False)
                bar.update(done - bar.n)  # through update: the rate shown follows it
                bar.refresh()
                if closing:
                    break
                time.sleep(DRAW_INTERVAL_S)  # what changes meanwhile is drawn at once
            bar.close()
        except (OSError, ValueError):  # stderr closed or broken: nothing more can be shown
            pass
