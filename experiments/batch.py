"""Batches of trials (seeds x grasp backends x babbling modes) on a Dask cluster.

Without a scheduler address the batch runs on a `LocalCluster` of worker processes on this
machine; with one (`tcp://HOST:PORT`) the same batch runs on an existing cluster, e.g. workers
started on PBS or SLURM nodes by dask-jobqueue (README). Each trial is one Dask task that runs
(or resumes) the trial and evaluates it, so:
- rerunning a batch skips evaluated trials and resumes unfinished ones from their checkpoints;
- a worker that dies mid-trial has its task rescheduled by Dask on another worker, where it
  resumes from the trial's last checkpoint: nothing is lost beyond that, nothing duplicated.
"""

from __future__ import annotations

import dataclasses
import json
import logging
import os
import threading
import time
from dataclasses import dataclass, field
from importlib import resources
from pathlib import Path

from tqdm import tqdm

from experiments import storage
from experiments.cli_args import stored_profiles
from experiments.evaluation import EVAL_FILE, EvaluationSettings, evaluate_trial
from experiments.lock import DirectoryLock
from experiments.trial import CHECKPOINT_FILE, TrialSettings, run_trial

TIMING_FILE = "timing.json"
# How long to wait for a scheduler that does not answer.
CONNECT_TIMEOUT_S = 10
# How long a batch task waits for another writer of its trial to finish (s): longer than a
# trial of the paper profile takes on one core.
LOCK_WAIT_S = 4 * 3600


class BatchError(Exception):
    """A batch that cannot run as asked; the message says why."""


@dataclass(frozen=True)
class BatchSpec:
    """Which trials a batch holds and how each is run and evaluated."""

    grasps: tuple[str, ...] = ("kinematic", "physical")
    babbling: tuple[str, ...] = ("random",)
    seeds: tuple[int, ...] = (0, 1, 2)
    iterations: int = 1000
    checkpoint_every: int = 1000
    eval_placements: int = 100
    stick_return: str = "out_of_reach"
    preset: str = "study"
    overrides: dict = field(default_factory=dict)
    description: str = field(default="", compare=False)

    def trials(self) -> list[tuple[str, TrialSettings]]:
        """(directory name, settings) of every trial, in a stable order."""
        out = []
        for grasp in self.grasps:
            for babbling in self.babbling:
                for seed in self.seeds:
                    name = f"{grasp}-{babbling}-seed{seed:04d}"
                    settings = TrialSettings(
                        grasp=grasp,
                        iterations=self.iterations,
                        seed=seed,
                        babbling=babbling,
                        checkpoint_every=min(self.checkpoint_every, self.iterations),
                        stick_return=self.stick_return,
                        preset=self.preset,
                        overrides=self.overrides,
                    )
                    out.append((name, settings))
        return out


def load_spec(
    profile: str | None = None, config_file: str | os.PathLike | None = None
) -> BatchSpec:
    """A stored profile (experiments/profiles/NAME.json) or a JSON file of the same form."""
    if (profile is None) == (config_file is None):
        raise BatchError("give exactly one of --profile NAME or --config FILE")
    if profile is not None:
        if profile not in stored_profiles():
            choices = ", ".join(stored_profiles())
            raise BatchError(f"unknown profile {profile!r}: choose one of {choices}")
        text = resources.files("experiments").joinpath(f"profiles/{profile}.json").read_text()
        source = f"profile {profile}"
    else:
        path = Path(config_file)
        if not path.is_file():
            raise BatchError(f"batch config {path} does not exist")
        text, source = path.read_text(), str(path)
    try:
        raw = json.loads(text)
    except json.JSONDecodeError as exc:
        raise BatchError(f"{source} is not valid JSON ({exc})") from None
    known = {f.name for f in dataclasses.fields(BatchSpec)} - {"description"}
    unknown = sorted(set(raw) - known - {"description"})
    if unknown:
        raise BatchError(f"{source}: unknown field(s) {', '.join(unknown)}")
    seeds = raw.get("seeds", 3)
    seeds = tuple(range(seeds)) if isinstance(seeds, int) else tuple(int(s) for s in seeds)
    try:
        spec = BatchSpec(
            grasps=tuple(raw.get("grasps", ("kinematic", "physical"))),
            babbling=tuple(raw.get("babbling", ("random",))),
            seeds=seeds,
            iterations=int(raw.get("iterations", 1000)),
            checkpoint_every=int(raw.get("checkpoint_every", 1000)),
            eval_placements=int(raw.get("eval_placements", 100)),
            stick_return=str(raw.get("stick_return", "out_of_reach")),
            preset=str(raw.get("preset", "study")),
            overrides=dict(raw.get("overrides", {})),
            description=raw.get("description", ""),
        )
        spec.trials()  # validates every trial's settings
    except Exception as exc:
        raise BatchError(f"{source}: {exc}") from None
    if not spec.seeds:
        raise BatchError(f"{source}: no seeds")
    return spec


def is_complete(trial_dir: Path) -> bool:
    """Whether a trial ran to its end and was evaluated."""
    if not (trial_dir / EVAL_FILE).exists() or not (trial_dir / CHECKPOINT_FILE).exists():
        return False
    try:
        _, meta = storage.read_arrays(trial_dir / CHECKPOINT_FILE)
    except storage.CorruptFileError:
        return False
    return bool(meta.get("finished"))


def run_and_evaluate(trial_dir: str, settings: TrialSettings, eval_placements: int) -> dict:
    """One batch task: run or resume the trial, then evaluate it. Safe to run again."""
    path = Path(trial_dir)
    # A worker stopped mid-trial (a batch ended by Ctrl-C) must leave no multiprocessing
    # semaphore behind, which tqdm's default lock is: the resource tracker would complain after
    # the batch's last line. A worker draws no bar; a thread lock is enough.
    tqdm.set_lock(threading.RLock())
    # Dask may run a task again while its first attempt still runs on a worker it lost touch
    # with: the second waits for the first to end instead of writing beside it.
    lock = DirectoryLock(path).acquire(wait_s=LOCK_WAIT_S)
    try:
        resume = (path / "config.json").exists()
        start = time.perf_counter()
        trial = run_trial(path, settings, resume=resume, progress=False)
        if trial.elapsed is not None:
            # Only the iterations run now are timed, so resumed trials still give a fair cost.
            storage.write_json(
                path / TIMING_FILE,
                {
                    "seconds": trial.elapsed,
                    "iterations": settings.iterations - trial.start_iteration,
                },
            )
        summary = evaluate_trial(path, EvaluationSettings(n_placements=eval_placements))
        summary["wall_seconds"] = time.perf_counter() - start
    finally:
        lock.release()
    return summary


def _client(scheduler: str | None, n_workers: int | None):
    """A Dask client: to the given scheduler, or to a new LocalCluster of worker processes."""
    from distributed import Client, LocalCluster

    # The scheduler's and nannies' INFO lines would bury the progress bar.
    logging.getLogger("distributed").setLevel(logging.WARNING)
    if scheduler is not None:
        try:
            return Client(scheduler, timeout=f"{CONNECT_TIMEOUT_S}s"), None
        except (OSError, TimeoutError) as exc:
            raise BatchError(
                f"no Dask scheduler answered at {scheduler} within {CONNECT_TIMEOUT_S} s ({exc})"
            ) from None
    cluster = LocalCluster(
        n_workers=n_workers or os.cpu_count() or 1,
        threads_per_worker=1,
        processes=True,
        dashboard_address=None,
        silence_logs=logging.ERROR,
    )
    return Client(cluster), cluster


def run_batch(
    spec: BatchSpec,
    out_dir: str | os.PathLike,
    scheduler: str | None = None,
    n_workers: int | None = None,
    client=None,
    progress: bool = True,
) -> dict[str, dict]:
    """Run every trial of `spec` under out_dir (skipping completed ones); returns the
    evaluation summary of each trial run now, by name. Trials that fail are reported and the
    others go on; BatchError at the end names the failures."""
    from distributed import as_completed

    out = Path(out_dir)
    if out.exists() and not out.is_dir():
        raise BatchError(f"{out} is a file, not a directory")
    try:
        out.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise BatchError(f"cannot create {out}: {exc.strerror}") from None
    todo = [(n, s) for n, s in spec.trials() if not is_complete(out / n)]
    skipped = len(spec.trials()) - len(todo)
    if not todo:
        if progress:
            print(f"{out}: all {skipped} trials already complete")
        return {}
    own_cluster = None
    if client is None:
        client, own_cluster = _client(scheduler, n_workers)
    results: dict[str, dict] = {}
    failures: dict[str, str] = {}
    try:
        futures = {
            client.submit(
                run_and_evaluate,
                str(out / name),
                settings,
                spec.eval_placements,
                key=name,
                pure=False,
                retries=2,
            ): name
            for name, settings in todo
        }
        # `with`: the bar's line is ended however the batch ends (Ctrl-C, SIGTERM).
        with tqdm(total=len(todo), disable=not progress, desc="batch", unit="trial") as bar:
            if skipped and progress:
                bar.write(f"skipping {skipped} complete trial(s)")
            for future in as_completed(futures):
                name = futures[future]
                try:
                    results[name] = future.result()
                except Exception as exc:  # a trial's error must not stop the others
                    failures[name] = f"{type(exc).__name__}: {exc}"
                bar.update(1)
                # Dask may queue more tasks on a worker than it has threads: at most one task per
                # thread runs, the rest of the unfinished ones wait.
                unfinished = sum(not f.done() for f in futures)
                running = min(unfinished, sum(client.nthreads().values()))
                waiting = unfinished - running
                bar.set_postfix(
                    done=len(results), running=running, waiting=waiting, failed=len(failures)
                )
    except KeyboardInterrupt:  # Ctrl-C or SIGTERM (experiments/cli_faults.py)
        # The workers' complaints about being closed mid-trial would follow the command's one
        # line; their trials resume from their checkpoints.
        logging.getLogger("distributed").setLevel(logging.CRITICAL)
        raise
    finally:
        if own_cluster is not None:
            client.close()
            own_cluster.close()
    if failures:
        listed = "; ".join(f"{n} ({e})" for n, e in sorted(failures.items()))
        raise BatchError(f"{len(failures)} trial(s) failed: {listed}")
    return results
