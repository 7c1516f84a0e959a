"""How a `playroom` command ends (experiments/cli/main.py): one line on stderr and an exit code,
never a traceback, whether the request was wrong, the machine failed the work, or the command
was stopped. Each command's line says what was kept and how to go on.

Exit codes:
- 0: done.
- 1: the machine failed the work: a file could not be written or read (disk full, a file
  system turned read-only, an I/O error). What was written before is kept as the line says (a
  trial up to its last checkpoint; a report, comparison, ablation table or evaluation is
  written whole or not at all); run the same command again once the fault is mended.
- 2: the request cannot be done as asked (`UsageError`): bad arguments or settings, a
  directory that holds something else or cannot be written, found before any work.
- 130 (SIGINT, Ctrl-C) and 143 (SIGTERM): stopped; 128 + the signal's number, as shells do.
"""

from __future__ import annotations

import argparse
import errno
import shlex
import signal
import sys
import warnings
from collections.abc import Callable, Iterator
from contextlib import contextmanager

from experiments.cli.args import UsageError
from experiments.run import stop_requests
from experiments.run.stop_requests import Terminated
from sim.vocal.diva.data import DivaDataMissing

EXIT_FAULT = 1
EXIT_USAGE = 2
EXIT_SIGINT = 128 + signal.SIGINT
EXIT_SIGTERM = 128 + signal.SIGTERM


@contextmanager
def signals_as_exceptions() -> Iterator[None]:
    """While the block runs, SIGTERM raises `Terminated` and SIGINT KeyboardInterrupt, as
    Python does, and both are recorded so that a raise dropped inside a finalizer is raised
    again (experiments/run/stop_requests.py); both handlers are restored afterwards. A SIGINT
    the process was started ignoring (as under nohup) stays ignored. Outside the main thread,
    where no handler can be set, nothing changes."""
    try:
        previous = {signal.SIGTERM: signal.signal(signal.SIGTERM, stop_requests.handle)}
    except ValueError:  # not the main thread
        yield
        return
    previous[signal.SIGINT] = signal.getsignal(signal.SIGINT)
    if previous[signal.SIGINT] is signal.default_int_handler:
        signal.signal(signal.SIGINT, stop_requests.handle)
    try:
        yield
    finally:
        for signum, handler in previous.items():
            signal.signal(signum, handler)
        stop_requests.clear()


def _ignore_signals() -> None:
    """While the last line is written: a second Ctrl-C must not turn it into a traceback (the
    handlers are restored by `signals_as_exceptions`)."""
    for signum in (signal.SIGINT, signal.SIGTERM):
        try:
            signal.signal(signum, signal.SIG_IGN)
        except ValueError:  # not the main thread
            return


def fault_line(exc: OSError) -> str:
    """An OSError as one line naming the file and the system's reason."""
    from experiments.trial_dir import storage

    reason = storage.reason(exc)
    if isinstance(exc, storage.WriteError):
        return f"cannot write {exc.filename}: {reason}"
    if exc.filename is not None:
        return f"{exc.filename}: {reason}"
    return reason


# What each command keeps when it stops early, and how to go on ----------------------------


def _command(argv: list[str], add: str | None = None, drop: str | None = None) -> str:
    words = [w for w in argv if w != drop]
    if add is not None and add not in words:
        words.append(add)
    return shlex.join(["playroom", *words])


def _run_kept(args: argparse.Namespace, argv: list[str], then: str) -> str:
    """What an interrupted or failed `playroom run` kept, and the command that continues it
    (`then`: what to do first, e.g. "free some space, then ")."""
    from experiments.trial_dir.reading import open_for_reading

    trial = open_for_reading(args.out)
    if not trial.has_config():  # stopped before the trial was set up
        again = _command(argv, drop="--resume")
        return f"nothing of the trial was kept; {then}start it again with: {again}"
    iteration = trial.kept_iteration()
    if iteration is not None:
        kept = f"the trial is kept up to its checkpoint at iteration {iteration}"
    else:
        kept = "the trial had no checkpoint yet"
    return f"{kept}; {then}resume with: {_command(argv, add='--resume')}"


def _batch_kept(args: argparse.Namespace, argv: list[str], then: str) -> str:
    return (
        "finished trials are kept and unfinished ones resume from their last checkpoints; "
        f"{then}rerun the same command to resume: {_command(argv)}"
    )


def _eval_kept(args: argparse.Namespace, argv: list[str], then: str) -> str:
    return "the trial's evaluation files are as they were"


def _baseline_kept(args: argparse.Namespace, argv: list[str], then: str) -> str:
    return (
        "each toy's policy trained in full is kept (a policy stopped midway starts again), and "
        f"finished runs are kept; {then}rerun the same command to resume: {_command(argv)}"
    )


def _cluster_closed(args: argparse.Namespace, argv: list[str], then: str) -> str:
    if args.print_script:
        return "nothing was submitted"
    return (
        "its scheduler is closed and its jobs cancelled; a batch sent there stops, and resumes "
        "when rerun on a new cluster's scheduler"
    )


def _nothing_written(args: argparse.Namespace, argv: list[str], then: str) -> str:
    return "nothing was written"


KEPT: dict[str, Callable[[argparse.Namespace, list[str], str], str]] = {
    "run": _run_kept,
    "batch": _batch_kept,
    "cluster": _cluster_closed,
    "eval": _eval_kept,
    "report": _nothing_written,
    "compare": _nothing_written,
    "ablations": _nothing_written,
    "ladder": _nothing_written,
    "factorial": _nothing_written,
    "rl-baseline": _baseline_kept,
    "rl-compare": _nothing_written,
    "replay": _nothing_written,
    "voice-memory": _nothing_written,
}


def _kept(args: argparse.Namespace, argv: list[str], then: str = "") -> str:
    """ "; what was kept" for the command, or "" where there is nothing to say."""
    tell = KEPT.get(args.command)
    if tell is None:
        return ""
    try:
        return f"; {tell(args, argv, then)}"
    except OSError:  # the trial directory cannot even be read: say only what failed
        return ""


@contextmanager
def warnings_as_lines(prefix: str) -> Iterator[None]:
    """While the block runs, each warning is one line on stderr, `PREFIX warning: ...`, once
    (what Python prints by default is two lines, the second one of the project's source)."""
    shown: set[str] = set()

    def show(message, category, filename, lineno, file=None, line=None) -> None:
        text = " ".join(str(message).split())
        if text not in shown:
            shown.add(text)
            print(f"{prefix} warning: {text}", file=sys.stderr, flush=True)

    with warnings.catch_warnings():
        warnings.showwarning = show
        yield


def run_command(args: argparse.Namespace, argv: list[str]) -> int:
    """Run the parsed command; its exit code (module docstring). Every way out but success
    prints one line on stderr, `playroom COMMAND: ...`; so does each warning."""
    prefix = f"playroom {args.command}:"
    with signals_as_exceptions(), warnings_as_lines(prefix):
        try:
            args.func(args)
        except (UsageError, DivaDataMissing) as exc:  # DIVA's data is the user's to install
            print(f"{prefix} error: {exc}", file=sys.stderr)
            return EXIT_USAGE
        except OSError as exc:
            _ignore_signals()
            hint = _kept(args, argv, "free some space, then " if exc.errno == errno.ENOSPC else "")
            print(f"{prefix} error: {fault_line(exc)}{hint}", file=sys.stderr, flush=True)
            return EXIT_FAULT
        except KeyboardInterrupt as exc:
            _ignore_signals()
            print(f"{prefix} interrupted{_kept(args, argv)}", file=sys.stderr, flush=True)
            return EXIT_SIGTERM if isinstance(exc, Terminated) else EXIT_SIGINT
    return 0
