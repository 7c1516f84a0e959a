"""Batches of trials (seeds x grasp backends x babbling modes) on a Dask cluster.

Without a scheduler address the batch runs on a `LocalCluster` of worker processes on this
machine; with one (`tcp://HOST:PORT`) the same batch runs on an existing cluster, e.g. workers
started on PBS or SLURM nodes by dask-jobqueue (README). Each trial is one Dask task that runs
(or resumes) the trial and evaluates it, in its own world and in the batch's eval worlds
(experiments/trial_dir/eval_worlds.py), so:
- rerunning a batch skips evaluated trials and resumes unfinished ones from their checkpoints;
  a trial whose evaluations in the eval worlds are not all complete and intact has only those
  made;
- a worker that dies mid-trial has its task rescheduled by Dask on another worker, where it
  resumes from the trial's last checkpoint: nothing is lost beyond that, nothing duplicated.
"""

from __future__ import annotations

import dataclasses
import hashlib
import json
import logging
import os
import sys
import threading
import time
import uuid
from collections.abc import Callable
from concurrent.futures import CancelledError
from pathlib import Path

from tqdm import tqdm

from experiments.batch_files import BATCH_FILE
from experiments.batches import scheduler as dask_scheduler
from experiments.batches import worker_check, workers
from experiments.batches.cluster_settings import RETRIES, WORKER_WAIT_S
from experiments.batches.directory import check_directory
from experiments.batches.progress import (
    REPORT_EVERY,
    REPORT_INTERVAL_S,
    BatchProgress,
    dashboard_link,
    reporter,
)
from experiments.batches.spec import BatchError, BatchSpec, spec_record
from experiments.measure.evaluation import EvaluationSettings
from experiments.measure.trial_evaluation import evaluate_trial
from experiments.run import estimate
from experiments.run.settings import TrialSettings
from experiments.run.trial import run_trial
from experiments.trial_dir import storage
from experiments.trial_dir.config_file import with_added_settings
from experiments.trial_dir.errors import TrialError
from experiments.trial_dir.eval_worlds import EvalWorldError, own_world
from experiments.trial_dir.lock import DirectoryLock, DirectoryLocked
from experiments.trial_dir.reading import open_for_reading
from experiments.trial_dir.writing import write_timing
from sim.vocal.diva.data import DivaDataError, DivaDataMissing

# How long a batch task waits for another writer of its trial to finish (s): longer than a
# trial of the paper profile takes on one core.
LOCK_WAIT_S = 4 * 3600
# Failures that running the trial again would only repeat: a damaged or foreign trial
# directory, settings its files refuse, another writer past the wait, the user's DIVA data
# missing. A task returns them (`TrialFailed`) instead of raising, so that Dask neither retries
# them nor logs its "Compute Failed" traceback, three times, before the batch's one line.
DETERMINISTIC = (
    TrialError,
    storage.CorruptFileError,
    DirectoryLocked,
    DivaDataError,
    DivaDataMissing,
)


@dataclasses.dataclass(frozen=True)
class TrialFailed:
    """What a batch task returns for a failure of its trial that a retry would repeat: the
    error's type and message, on one line."""

    error: str


def is_complete(trial_dir: Path) -> bool:
    """Whether a trial ran to its end, is whole (its own checkpoint, logs complete up to it)
    and was evaluated there: what a rerun may skip. Whatever is not (a truncated eval.json,
    a lost log chunk) is run again, which evaluates it again or reports the damage."""
    trial = open_for_reading(trial_dir)
    try:
        config = trial.config_json()
        # Read whole, with the memory segments it names (a damaged one is run again).
        _, meta = trial.checkpoint_arrays()
        # As recorded and this trial's (eval_record), else evaluated again.
        evaluation = trial.evaluation()
        summary = evaluation.summary(config, "", warn=False)
        if not meta.get("finished"):
            return False
        if summary.get("evaluated_at_iteration") != meta["iteration"]:
            return False
        trial.check_checkpoint_identity(meta, config)
        # Every file as recorded (manifest, eval.json): a damaged one is run again, which mends
        # what can be mended (backend.json, an evaluation) and names what cannot.
        trial.check_files(meta, with_added_settings(config))
        evaluation.check_tables(summary)
    except (OSError, KeyError, TypeError, storage.CorruptFileError, TrialError):
        return False
    return True


def eval_world_complete(trial_dir: Path, world: str, placements: int) -> bool:
    """Whether a finished trial's evaluation in eval world `world` needs no work: the world is
    the trial's own (its own evaluation is it: `is_complete`), or `eval-in-<world>/` holds an
    evaluation at the trial's last checkpoint, on `placements` placements, of the world as
    declared now, every table as its eval.json lists it."""
    trial = open_for_reading(trial_dir)
    try:
        config = trial.config()
        if own_world(config, world):
            return True
        evaluation = trial.evaluation_elsewhere(world)
        summary = evaluation.summary(config, "", False)
        meta = trial.checkpoint_meta()
        if summary.get("n_placements") != placements:
            return False
        if summary.get("evaluated_at_iteration") != meta["iteration"]:
            return False
        evaluation.check_world(config, world, summary)
    except (OSError, KeyError, TypeError, storage.CorruptFileError, EvalWorldError):
        return False
    return True


def run_and_evaluate(
    trial_dir: str,
    settings: TrialSettings,
    eval_placements: int,
    topic: str | None = None,
    progress_topic: str | None = None,
    report_every: int = REPORT_EVERY,
    report_interval_s: float = REPORT_INTERVAL_S,
    eval_worlds: tuple[str, ...] = (),
) -> dict | TrialFailed:
    """One batch task: run or resume the trial, then evaluate it, in its own world and in
    each of `eval_worlds`; its evaluation summary, or `TrialFailed` for a failure a retry would
    repeat (DETERMINISTIC). Safe to run again: a trial complete and evaluated on
    `eval_placements` is neither run nor evaluated again, nor is an evaluation in an eval world
    that is complete and intact. A wait for another writer of the trial is told to the client
    listening on `topic`, the iteration the trial reached (looked at every `report_every`, told
    at most every `report_interval_s`) to the one listening on `progress_topic`."""
    try:
        return _run_and_evaluate(
            Path(trial_dir), settings, eval_placements, topic, progress_topic, report_every,
            report_interval_s, eval_worlds,
        )  # fmt: skip
    except DETERMINISTIC as exc:
        return TrialFailed(f"{type(exc).__name__}: {' '.join(str(exc).split())}")


def _own_part_complete(path: Path, placements: int) -> dict | None:
    """The evaluation summary of a trial that is complete (`is_complete`) and was evaluated on
    `placements` placements, else None."""
    if not is_complete(path):
        return None
    trial = open_for_reading(path)
    summary = trial.evaluation().summary(trial.config_json(), "", False)
    return summary if summary.get("n_placements") == placements else None


def _run_and_evaluate(
    path: Path,
    settings: TrialSettings,
    eval_placements: int,
    topic: str | None,
    progress_topic: str | None,
    report_every: int,
    report_interval_s: float,
    eval_worlds: tuple[str, ...] = (),
) -> dict:
    # A worker stopped mid-trial (a batch ended by Ctrl-C) must leave no multiprocessing
    # semaphore behind, which tqdm's default lock is: the resource tracker would complain after
    # the batch's last line. A worker draws no bar; a thread lock is enough.
    tqdm.set_lock(threading.RLock())
    # Dask may run a task again while its first attempt still runs on a worker it lost touch
    # with: the second waits for the first to end instead of writing beside it. So does a
    # task whose trial another batch or `playroom run` writes: the user hears of it.
    try:
        lock = DirectoryLock(path).acquire()
    except DirectoryLocked as exc:
        dask_scheduler.tell_client(
            topic,
            f"waiting (up to {LOCK_WAIT_S / 3600:g} h) for another writer of {path.name} to "
            f"finish: {exc}",
        )
        lock = DirectoryLock(path).acquire(wait_s=LOCK_WAIT_S)
    try:
        start = time.perf_counter()
        evaluation = EvaluationSettings(n_placements=eval_placements)
        # A rerun that only asks for eval worlds: the trial and its own evaluation are kept.
        summary = _own_part_complete(path, eval_placements)
        if summary is None:
            resume = open_for_reading(path).has_config()
            trial = run_trial(
                path, settings, resume=resume, progress=False,
                report=reporter(progress_topic, path.name, report_interval_s),
                report_every=report_every,
            )  # fmt: skip
            if trial.elapsed is not None:
                # Only the iterations run now are timed: resumed trials still give a fair cost.
                write_timing(path, trial.elapsed, settings.iterations - trial.start_iteration)
            summary = evaluate_trial(path, evaluation)
        tested = {}
        for world in eval_worlds:
            if not eval_world_complete(path, world, eval_placements):
                tested[world] = evaluate_trial(path, evaluation, world=world)["competence"]
        if eval_worlds:  # the competences of the evaluations made now
            summary["eval_worlds"] = tested
        summary["wall_seconds"] = time.perf_counter() - start
    finally:
        lock.release()
    return summary


def task_key(name: str, trial_dir: Path, settings: TrialSettings, placements: int, run: str) -> str:
    """The Dask key of a trial's task: its name (as the dashboard shows it), a digest of where
    and what it runs, and the run's token. Tasks of one key are one task to a scheduler, shared
    by every client that submits it: so no other batch, configuration or run may ever share a
    key (a second run of the same batch waits on the trials' locks instead)."""
    what = json.dumps([str(trial_dir), dataclasses.asdict(settings), placements], sort_keys=True)
    return f"{name}-{hashlib.sha256(what.encode()).hexdigest()[:8]}-{run}"


def run_batch(
    spec: BatchSpec,
    out_dir: str | os.PathLike,
    scheduler: str | None = None,
    n_workers: int | None = None,
    client=None,
    progress: bool = True,
    notify: Callable[[str], None] | None = None,
    report_every: int = REPORT_EVERY,
    report_interval_s: float = REPORT_INTERVAL_S,
    retries: int = RETRIES,
    worker_wait_s: float = WORKER_WAIT_S,
) -> dict[str, dict]:
    """Run every trial of `spec` under out_dir (skipping completed ones); returns the
    evaluation summary of each trial run now, by name. Trials that fail are reported and the
    others go on; BatchError at the end names the failures, or at once says the scheduler is
    not one or was lost. The Dask dashboard's link is printed on stderr first; `notify` gets
    the lines said while trials run (default: stderr); `progress`: a bar of the iterations
    done across the trials, moved at most every `report_interval_s` by each trial (looked at
    every `report_every` iterations)
    (experiments/batches/progress.py). Every worker is checked before it runs a trial
    (experiments/batches/workers.py): BatchError naming an unfit one, and one when no worker
    comes within `worker_wait_s`; a trial is run again `retries` times after its worker dies
    or a fault that may pass."""
    # Workers may run in another directory, or on another machine sharing the file system:
    # they are sent the path the user meant, not one relative to where they run.
    out = Path(os.path.abspath(Path(out_dir).expanduser()))
    if out.exists() and not out.is_dir():
        raise BatchError(f"{out} is a file, not a directory")
    try:
        check_directory(spec, out)  # one batch per directory, refused before anything is written
    except OSError as exc:
        raise BatchError(f"cannot read {out}: {storage.reason(exc)}") from None
    todo = [
        (n, s)
        for n, s in spec.trials()
        if not is_complete(out / n)
        or not all(eval_world_complete(out / n, w, spec.eval_placements) for w in spec.eval_worlds)
    ]
    skipped = len(spec.trials()) - len(todo)
    try:  # the whole batch's disk, before anything is written or a worker started
        told = estimate.check_batch_fits(out, [(out / n, s) for n, s in todo])
    except TrialError as exc:
        raise BatchError(str(exc)) from None
    if told is not None and progress:
        print(f"batch: {told}", file=sys.stderr)
    if not todo:
        _record(spec, out)
        if progress:
            print(f"{out}: all {skipped} trials already complete")
        return {}
    own_cluster = None
    if client is None:
        try:
            client, own_cluster = dask_scheduler.connect(scheduler, n_workers)
        except dask_scheduler.SchedulerError as exc:
            raise BatchError(str(exc)) from None
    shown = BatchProgress({n: s.iterations for n, s in todo}, enabled=progress)
    if notify is None:
        notify = lambda line: shown.say(f"batch: {line}")  # noqa: E731
    run = uuid.uuid4().hex[:8]
    topic = f"playroom-batch-{run}"
    progress_topic = f"{topic}-progress"
    results: dict[str, dict] = {}
    failures: dict[str, str] = {}
    listening = recorded = made = False
    token: Path | None = None  # the run's token file, once written
    try:  # from here on, the cluster this batch started is closed however the batch ends
        where = scheduler or "the batch's local cluster"
        workers.wait_for_workers(client, where, worker_wait_s)
        try:
            made = workers.created(out)
            token, secret = workers.write_token(out, run)
        except OSError as exc:
            raise BatchError(f"cannot write into {out}: {exc.strerror}") from None
        expected = {"code": workers.code_expected(), "token_path": str(token), "token": secret}
        workers.check_workers(client, expected)
        workers.allow_failures(client, retries)
        _record(spec, out)
        recorded = True
        # Where to watch the cluster (tasks, workers, memory), whichever cluster it is.
        link = dashboard_link(client)
        where = link or "none (the scheduler serves none)"
        shown.say(f"batch: Dask dashboard: {where}")
        dask_scheduler.listen(client, topic, notify)
        shown.listen(client, progress_topic)
        listening = True
        futures = {}
        for name, settings in todo:
            trial_dir = out / name
            key = task_key(name, trial_dir, settings, spec.eval_placements, run)
            # The worker is checked on itself before it runs the trial (one that joined late).
            future = client.submit(
                worker_check.guarded_trial, expected, str(trial_dir),
                dataclasses.asdict(settings), spec.eval_placements, topic, progress_topic,
                report_every, report_interval_s, spec.eval_worlds, key=key, pure=False,
                retries=retries,
            )  # fmt: skip
            futures[future] = name
        if skipped and progress:
            shown.say(f"skipping {skipped} complete trial(s)")
        watch = workers.WorkerWatch(client, where, shown.say)
        for future in dask_scheduler.as_finished(futures, watch.look):
            name = futures[future]
            try:
                result = future.result()
            except Exception as exc:  # a trial's error must not stop the others
                # Only a lost scheduler cancels a batch's tasks: its keys are its own.
                if isinstance(exc, CancelledError) or dask_scheduler.scheduler_lost(client):
                    raise dask_scheduler.lost_error(scheduler, len(todo) - len(results)) from None
                failures[name] = dask_scheduler.failure_text(exc, retries)
            else:
                if isinstance(result, dict) and worker_check.UNFIT in result:
                    raise BatchError(
                        f"{result[worker_check.UNFIT]}; the batch stopped (the trials other "
                        "workers run resume from their checkpoints when it is run again)"
                    )
                if isinstance(result, TrialFailed):
                    failures[name] = result.error
                else:
                    results[name] = result
            shown.ended(name, failed=name in failures)
    except KeyboardInterrupt:  # Ctrl-C or SIGTERM (experiments/cli/faults.py)
        # The workers' complaints about being closed mid-trial would follow the command's one
        # line; their trials resume from their checkpoints.
        logging.getLogger("distributed").setLevel(logging.CRITICAL)
        raise
    finally:
        if token is not None:
            workers.remove_token(token)
        if not recorded:  # refused before anything was written: the directory made now goes
            workers.undo_created(out, made)
        try:
            shown.close()  # waits for stderr: a second Ctrl-C there still closes the cluster
        finally:
            if own_cluster is not None:
                client.close()
                own_cluster.close()
            elif listening and not dask_scheduler.scheduler_lost(client):
                client.unsubscribe_topic(topic)
                client.unsubscribe_topic(progress_topic)
    if failures:
        listed = "; ".join(f"{n} ({e})" for n, e in sorted(failures.items()))
        raise BatchError(f"{len(failures)} trial(s) failed: {listed}")
    return results


def _record(spec: BatchSpec, out: Path) -> None:
    """Write what the batch is into its directory (batch.json): its reports read the size of
    the study's random reference from it (experiments/analysis/batch_record.py)."""
    try:
        storage.write_json(out / BATCH_FILE, spec_record(spec))
    except OSError as exc:
        raise BatchError(f"cannot write {out / BATCH_FILE}: {exc.strerror}") from None
