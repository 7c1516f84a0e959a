"""A request to stop (SIGINT, SIGTERM) that is not lost where Python ignores exceptions.

The command line turns both signals into exceptions (experiments/cli/faults.py). Python raises
them wherever the main thread is, and one raised inside a finalizer (`__del__`: pyarrow's
ParquetWriter has one, run after every log chunk a trial writes) is printed as "Exception
ignored" and dropped: Ctrl-C then did nothing, and the trial ran on (measured: 1 of 25
interrupts of `playroom run --checkpoint-every 50`). The handlers here also record the request,
and long loops call `raise_if_requested()` once a round: a dropped request is raised again there.
"""

from __future__ import annotations

import signal


class Terminated(KeyboardInterrupt):
    """SIGTERM, raised in the main thread as Ctrl-C raises KeyboardInterrupt: every `finally`
    on the way out runs (a trial's lock released, a batch's cluster closed), and no
    `except Exception` mistakes it for a failure of the work."""


_requested: int | None = None  # the signal of a request not yet acted on


def _exception(signum: int) -> KeyboardInterrupt:
    return Terminated() if signum == signal.SIGTERM else KeyboardInterrupt()


def handle(signum: int, frame: object) -> None:
    """The signal handler: record the request, then raise it where the main thread is."""
    global _requested
    _requested = signum
    raise _exception(signum)


def raise_if_requested() -> None:
    """Raise a request whose first raise was dropped (a no-op when none was made)."""
    if _requested is not None:
        raise _exception(_requested)


def clear() -> None:
    """The request has been acted on (the command ends, or a handler is uninstalled)."""
    global _requested
    _requested = None
