"""What a batch shows while it runs: one bar of the iterations done across its trials, which
advances within a trial, with the running trials named beside it, and the Dask dashboard's link.

Each batch task tells the client the iteration its trial reached (about once a second,
through the worker's event log: `distributed`'s `log_event`, one topic per batch
run); the client's subscription moves the bar. A task that runs again (a lost worker) reports
from where its trial resumes."""

from __future__ import annotations

import math
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

    def report(iteration: int) -> None:
        nonlocal last
        now = time.monotonic()
        if now - last >= min_interval_s:
            last = now
            worker.log_event(topic, {"trial": name, "iteration": iteration})

    return report


class BatchProgress:
    """The bar of a batch: `total` iterations over the trials to run (name -> iterations)."""

    def __init__(self, trials: dict[str, int], enabled: bool) -> None:
        self._lock = threading.Lock()  # reports arrive on the client's thread
        self._reached = dict.fromkeys(trials, 0)
        self._total = trials
        self._running: set[str] = set()
        self._counts = {"done": 0, "failed": 0}
        self.bar = tqdm(
            total=sum(trials.values()), disable=not enabled, desc="batch", unit="it",
            dynamic_ncols=True,
        )  # fmt: skip

    def reached(self, name: str, iteration: int) -> None:
        """A trial reports the iteration it reached."""
        with self._lock:
            if name not in self._reached:
                return
            self._running.add(name)
            step = min(iteration, self._total[name]) - self._reached[name]
            self._reached[name] += step
            self.bar.update(step)
            self._postfix()

    def ended(self, name: str, failed: bool) -> None:
        """A trial's task ended (run and evaluated, or failed)."""
        with self._lock:
            self._running.discard(name)
            self._counts["failed" if failed else "done"] += 1
            if not failed:  # its iterations count even where a report was missed
                self.bar.update(self._total[name] - self._reached[name])
                self._reached[name] = self._total[name]
            self._postfix()

    def listen(self, client, topic: str) -> None:
        """Move the bar with every report sent under `topic`."""

        def on_event(event: tuple) -> None:
            message = event[1]
            if isinstance(message, dict):
                self.reached(str(message.get("trial")), int(message.get("iteration", 0)))

        client.subscribe_topic(topic, on_event)

    def _postfix(self) -> None:
        running = sorted(self._running)
        named = ", ".join(running[:NAMED_RUNNING])
        more = len(running) - NAMED_RUNNING
        self.bar.set_postfix_str(
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
        """The trials that reported and have not ended, by name."""
        with self._lock:
            return sorted(self._running)

    def close(self) -> None:
        self.bar.close()
