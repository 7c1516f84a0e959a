"""What a Dask worker must be before it runs a trial of a batch, checked on the worker itself:
the project importable, at the submitter's version (its commit and the libraries that change
a trial's bits), and the batch directory seen at the submitter's path (a token the submitter
wrote there, read back).

This module is sent to the workers by value (`cloudpickle.register_pickle_by_value`, done by
experiments/batches/workers.py) and imports only the standard library at its top, so a worker
whose Python cannot import the project, or finds another copy of it first, still runs the
check and says what is wrong. Sent by reference, as the trial's own function is, the task
could not even be unpickled there: the worker died on `ModuleNotFoundError` and the batch
waited forever.

Everything crossing to and from a worker here is plain data (dicts, strings): a class of the
project would need the project to be unpickled, and a class sent by value arrives as another
class than the submitter's.
"""

from __future__ import annotations

import importlib
import importlib.util
import socket
from pathlib import Path
from typing import Any

# What a guarded task returns instead of a summary when its worker is unfit: {UNFIT: line}.
UNFIT = "unfit_worker"


def _where_found() -> str:
    """Where this Python finds the project's package `experiments`, for the line saying it
    could not import it."""
    try:
        spec = importlib.util.find_spec("experiments")
    except (ImportError, ValueError):
        spec = None
    if spec is None:
        return "it finds no package `experiments`"
    origin = spec.origin or next(iter(spec.submodule_search_locations or []), "?")
    return f"its Python finds `experiments` at {origin}"


def _worker_name() -> str:
    """This worker's address and host, as the user started it."""
    host = socket.gethostname()
    try:
        from distributed import get_worker

        return f"{get_worker().address} (host {host})"
    except (ImportError, ValueError):  # called outside a worker: a test, or the submitter
        return f"on host {host}"


def _version_differences(expected: dict, found: dict) -> list[str]:
    """What differs between the submitter's code record and this worker's: the commit (when
    both know theirs) and the versions of Python and of the computing libraries the submitter
    lists, one short phrase each."""
    out = []
    commit_a = (expected.get("source") or {}).get("commit")
    commit_b = (found.get("source") or {}).get("commit")
    if commit_a and commit_b and commit_a != commit_b:
        out.append(f"commit {commit_b[:10]} where the batch runs {commit_a[:10]}")
    elif bool(commit_a) != bool(commit_b):
        which = (found.get("source") or {}).get("where") or "unknown"
        out.append(f"code from an {which} where the batch runs commit {str(commit_a)[:10]}")
    theirs = found.get("versions") or {}
    for name, version in (expected.get("versions") or {}).items():
        if theirs.get(name) != version:
            out.append(f"{name} {theirs.get(name)} where the batch runs {version}")
    return out


def worker_problem(expected: dict[str, Any]) -> str | None:
    """Why this worker may not run a trial of the batch `expected` describes, in one line
    naming the worker and what to do; None when it may. `expected`: {"code": the submitter's
    `experiments.trial_dir.provenance.machine_record()`'s "source" and the "versions" to
    compare, "token_path": a file in the batch directory,
    "token": its content}."""
    name = _worker_name()
    try:
        provenance = importlib.import_module("experiments.trial_dir.provenance")
        # machine_record, which every version of the project since provenance has: an older
        # copy is told as another version, not as one that cannot be imported.
        found = provenance.machine_record()
    except Exception as exc:  # whatever another copy of the project raises on import
        why = f"{type(exc).__name__}: {' '.join(str(exc).split())}"
        return (
            f"worker {name} cannot import the project ({why}; {_where_found()}): start it "
            "from the project's environment (e.g. `.venv/bin/dask worker ADDRESS`)"
        )
    differences = _version_differences(expected["code"], found)
    if differences:
        return (
            f"worker {name} runs another version of the project ({'; '.join(differences)}): "
            "install the batch's version there (the same commit and constraints.txt) and "
            "restart the worker"
        )
    token_path = Path(expected["token_path"])
    try:
        token = token_path.read_text(encoding="utf-8")
    except FileNotFoundError:
        token = None
    except OSError as exc:
        return (
            f"worker {name} cannot read the batch directory {token_path.parent} "
            f"({exc.strerror}): every worker must see it at the same path, on a shared "
            "filesystem, with the right to write"
        )
    if token != expected["token"]:
        seen = "does not see" if token is None else "sees another directory at"
        return (
            f"worker {name} {seen} the batch directory {token_path.parent} (its token "
            f"{'is missing' if token is None else 'differs'}): every worker must see the "
            "batch directory at the same path on a filesystem shared with the submitter, or "
            "its trials would be written where the batch cannot read them"
        )
    return None


def guarded_trial(expected: dict[str, Any], trial_dir: str, settings: dict, *args: Any) -> Any:
    """A batch's task: the worker checked (`worker_problem`), then the trial run and evaluated
    (experiments/batches/runner.py `run_and_evaluate`, given `settings` as a dict of
    TrialSettings' fields and `args` after them); {UNFIT: line} for an unfit worker, which
    has then written nothing."""
    problem = worker_problem(expected)
    if problem is not None:
        return {UNFIT: problem}
    runner = importlib.import_module("experiments.batches.runner")
    trial_settings = importlib.import_module("experiments.run.settings").TrialSettings
    return runner.run_and_evaluate(trial_dir, trial_settings(**settings), *args)


def set_allowed_failures(allowed: int, dask_scheduler: Any) -> int:
    """Run on the scheduler (`client.run_on_scheduler`): how many times a task may see its
    worker die before the scheduler gives it up (KilledWorker); returns the number it had.
    It is the scheduler's for every client: a scheduler started for the batch, or one the
    user shares knowingly (docs/usage.md)."""
    before = dask_scheduler.allowed_failures
    dask_scheduler.allowed_failures = allowed
    return int(before)
