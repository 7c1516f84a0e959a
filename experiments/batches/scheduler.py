"""The Dask side of a batch: finding a scheduler that really is one, in a bounded time, and
telling the client what a task is waiting for.

`distributed.Client(address, timeout=...)` bounds only the TCP connection: the handshake read
after it waits as long as the peer keeps the socket open (a silent service hangs it for good),
and a service that answers something else has its bytes read as a frame length (a MemoryError
for "3.07 EiB", or a ValueError). So before a client is made, `check_scheduler` asks the
address who it is through distributed's own comm, under one deadline for the whole exchange,
and accepts only a scheduler's reply.
"""

from __future__ import annotations

import asyncio
import logging
import os
import time
from collections.abc import Callable, Iterator
from concurrent.futures import ThreadPoolExecutor

from experiments.run import stop_requests


class SchedulerError(Exception):
    """No usable Dask scheduler: the message says what was found instead, in one line."""


# How long to try to connect to a scheduler (s; distributed retries within it), and how much
# longer to wait for its first reply once connected.
CONNECT_TIMEOUT_S = 10
REPLY_TIMEOUT_S = 5
# How often a batch waiting for its trials looks for a stop request Python dropped (s).
STOP_POLL_S = 0.2


def check_address(address: str) -> None:
    """SchedulerError unless `address` is of a form distributed can connect to."""
    from distributed.comm.addressing import parse_address, parse_host_port
    from distributed.comm.registry import get_backend

    try:
        scheme, location = parse_address(address, strict=False)
        get_backend(scheme)
        if scheme in ("tcp", "tls"):
            _, port = parse_host_port(location)
            if not 0 < port < 65536:
                raise ValueError(f"port {port} out of range")
    except (ValueError, TypeError) as exc:
        raise SchedulerError(
            f"scheduler {address!r} is not an address ({exc}); give tcp://HOST:PORT"
        ) from None


async def _identity(address: str, timeout_s: float) -> dict:
    from distributed.comm import connect

    comm = await connect(address, timeout=timeout_s)
    try:
        await comm.write({"op": "identity", "reply": True})
        return await comm.read()
    finally:
        comm.abort()


def check_scheduler(address: str, timeout_s: float | None = None) -> None:
    """SchedulerError unless a Dask scheduler answers at `address`: within `timeout_s` to
    connect, and `REPLY_TIMEOUT_S` more for its reply."""
    timeout_s = CONNECT_TIMEOUT_S if timeout_s is None else timeout_s
    check_address(address)
    try:
        # In a thread of its own, so that a caller already inside an event loop can ask too.
        with ThreadPoolExecutor(1) as pool:
            exchange = asyncio.wait_for(_identity(address, timeout_s), timeout_s + REPLY_TIMEOUT_S)
            reply = pool.submit(asyncio.run, exchange).result()
    except TimeoutError:  # connected, but no reply
        raise SchedulerError(
            f"no Dask scheduler answered at {address} within {timeout_s + REPLY_TIMEOUT_S:g} s "
            "(something accepted the connection but did not answer as a scheduler)"
        ) from None
    except OSError as exc:  # refused, unreachable, unknown host, closed by the peer
        raise SchedulerError(
            f"no Dask scheduler answered at {address} within {timeout_s:g} s ({_reason(exc)})"
        ) from None
    except Exception:  # bytes read as a frame: MemoryError, ValueError, msgpack's errors
        reply = None
    if not isinstance(reply, dict) or reply.get("type") != "Scheduler":
        other = reply.get("type") if isinstance(reply, dict) else None
        found = f"a Dask {other} answered" if isinstance(other, str) else "something else answered"
        raise SchedulerError(
            f"{address} is not a Dask scheduler ({found} there); "
            "give the address `dask scheduler` prints"
        )


def _reason(exc: BaseException) -> str:
    """Why a connection failed, on one line: the system's error behind distributed's retries
    (refused, unreachable, unknown host), else what distributed saw."""
    from distributed.comm.core import CommClosedError

    if isinstance(exc, CommClosedError):
        return "the connection was closed before a scheduler's reply"
    reason = "nothing accepted the connection"
    seen: BaseException | None = exc
    while seen is not None:
        if isinstance(seen, OSError) and seen.errno is not None:  # the system's own error
            reason = seen.strerror or str(seen)
        seen = seen.__cause__ or seen.__context__
    return reason


# The workers of a cluster a batch starts itself. Dask's defaults wake a worker's event loop
# every 20 ms and sample its running task's stack every 10 ms, each time taking the GIL from
# the trial: trials two at a time on 2 cores ran 10% slower than outside Dask (0.25 against
# 0.23 ms an iteration). Ticked every second and sampled every 100 ms, they ran as fast as
# outside, and the dashboard's profile still fills. (Workers of a `--scheduler` are the user's:
# README, Evaluation, batches, reports.)
LOCAL_WORKER_CONFIG = {
    "distributed.admin.tick.interval": "1s",
    "distributed.worker.profile.interval": "100ms",
    "distributed.worker.profile.cycle": "10s",
}


def connect(scheduler: str | None, n_workers: int | None):
    """(client, own cluster): a client of the scheduler at `scheduler`, checked first, or of a
    new LocalCluster of worker processes on this machine (then also returned, to be closed)."""
    from distributed import Client, LocalCluster

    # The scheduler's and nannies' INFO lines would bury the progress bar.
    logging.getLogger("distributed").setLevel(logging.WARNING)
    # A lost scheduler is said by the batch in one line, not by the client's log.
    logging.getLogger("distributed.client").setLevel(logging.CRITICAL)
    if scheduler is not None:
        check_scheduler(scheduler)
        try:
            # The timeout also bounds how long a client tries to reconnect to a lost scheduler.
            return Client(scheduler, timeout=f"{CONNECT_TIMEOUT_S}s"), None
        except (OSError, TimeoutError) as exc:
            raise SchedulerError(
                f"no Dask scheduler answered at {scheduler} within {CONNECT_TIMEOUT_S} s "
                f"({_reason(exc)})"
            ) from None
    import dask

    # Its workers' settings are taken from this process's config when they start.
    with dask.config.set(LOCAL_WORKER_CONFIG):
        cluster = LocalCluster(
            n_workers=n_workers or os.cpu_count() or 1,
            threads_per_worker=1,
            processes=True,
            # Any free port: with None, distributed still serves HTTP on 8787 and warns when
            # another batch on this machine holds it.
            dashboard_address=":0",
            silence_logs=logging.ERROR,
        )
    return Client(cluster), cluster


def scheduler_lost(client) -> bool:
    """Whether `client` has lost its scheduler (it gives up reconnecting after its timeout,
    and cancels every future it held)."""
    return client.status not in ("running", "connecting", "newly-created")


def tell_client(topic: str | None, line: str) -> None:
    """From inside a task: send `line` to the client subscribed to `topic`. Outside a worker
    (a task called directly) there is no one to tell."""
    if topic is None:
        return
    from distributed import get_worker

    try:
        worker = get_worker()
    except ValueError:
        return
    worker.log_event(topic, line)


def listen(client, topic: str, notify: Callable[[str], None]) -> None:
    """Call `notify(line)` for every line a task sends under `topic`."""
    client.subscribe_topic(topic, lambda event: notify(str(event[1])))


def as_finished(futures: dict, look: Callable[[], None]) -> Iterator:
    """The futures as they finish (distributed's `as_completed`), looking every
    STOP_POLL_S, while none finishes, for a stop request whose exception Python dropped in a
    finalizer (experiments/run/stop_requests.py): as_completed alone would wait for the next
    trial to end, minutes, before the batch heard it; `look()` is called then too."""
    from distributed import as_completed

    finished = as_completed(futures)
    while finished.count():
        ready = finished.next_batch(block=False)
        if not ready:
            stop_requests.raise_if_requested()
            look()
            time.sleep(STOP_POLL_S)
        for future in ready:
            stop_requests.raise_if_requested()
            yield future


def lost_error(scheduler: str | None, unfinished: int) -> Exception:
    """The error of a batch whose scheduler went away: what to restart, then to run again.
    Workers of a user's scheduler exit when it goes (`dask worker` gives up reconnecting)."""
    # Here, not at the top: the command line's help imports this module and not the specs.
    from experiments.batches.spec import BatchError

    if scheduler is None:
        restart = "run the same command again"
    else:
        restart = (
            "start the scheduler again and its workers with it (`dask scheduler`, then `dask "
            "worker ADDRESS` on each machine, or `playroom cluster`: its workers exited with "
            "it), then run the same command again with the new address"
        )
    return BatchError(
        f"lost the Dask scheduler {'at ' + scheduler if scheduler else 'of the batch'} with "
        f"{unfinished} trial(s) unfinished; {restart}: complete trials are kept, the others "
        "resume from their checkpoints"
    )


def failure_text(exc: BaseException, retries: int) -> str:
    """A trial's failure on one line; a trial whose worker died once more than `retries`
    allows (Dask's KilledWorker) says so and what to do."""
    from distributed.scheduler import KilledWorker

    if isinstance(exc, KilledWorker):
        return (
            f"its worker died {retries + 1} times while running it (Dask's KilledWorker): run "
            "the batch again to resume it from its checkpoint, and allow more deaths with "
            "--retries N if workers are preempted"
        )
    return f"{type(exc).__name__}: {' '.join(str(exc).split())}"
