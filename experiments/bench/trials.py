"""Whole trials for `playroom bench trial`: timed from a fresh start, as a batch worker runs
them (voice, learning, logging, checkpoints and, for the replication's, the evaluation)."""

from __future__ import annotations

import math
import multiprocessing
import tempfile
import time
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

from experiments.measure.evaluation import EvaluationSettings
from experiments.measure.trial_evaluation import evaluate_trial
from experiments.run.settings import TrialSettings
from experiments.run.trial import run_trial
from models.layout import N_STEPS


def trial_seconds_per_iteration(grasp: str, iterations: int) -> tuple[float, float]:
    """(seconds per iteration, share of its control steps computed) of a trial of the default
    settings in `grasp`. The share is the compiled physical steps' (sim/compiled_steps.py: a
    movement at rest stops computing); NaN where none ran (the kinematic backend)."""
    with tempfile.TemporaryDirectory() as out:
        settings = TrialSettings(grasp=grasp, iterations=iterations, checkpoint_every=1000)
        start = time.perf_counter()
        trial = run_trial(out, settings, progress=False)
        seconds = (time.perf_counter() - start) / iterations
    computed = int(trial.room.physics.control_steps_computed[0])
    return seconds, (computed / (iterations * N_STEPS) if computed else math.nan)


def replication_trial_seconds(settings: TrialSettings, placements: int) -> tuple[float, float]:
    """(seconds of the trial, seconds of its evaluation) of one trial as a batch worker runs
    it: run from a fresh start, then evaluated (experiments/batches/runner.py)."""
    with tempfile.TemporaryDirectory() as out:
        start = time.perf_counter()
        run_trial(out, settings, progress=False)
        trial_s = time.perf_counter() - start
        start = time.perf_counter()
        evaluate_trial(Path(out), EvaluationSettings(n_placements=placements))
        return trial_s, time.perf_counter() - start


def replication_pair_seconds(
    settings: list[TrialSettings], placements: int
) -> list[tuple[float, float]]:
    """`replication_trial_seconds` of trials run at once, each in its own process (as two
    batch workers run them), after each process has loaded the memory's kernel."""
    # Fresh interpreters ("spawn"), as Dask's workers are: no state inherited from this one.
    context = multiprocessing.get_context("spawn")
    with ProcessPoolExecutor(len(settings), mp_context=context) as pool:
        return list(pool.map(_warm_replication_trial, settings, [placements] * len(settings)))


def _warm_replication_trial(settings: TrialSettings, placements: int) -> tuple[float, float]:
    from learner.indexed_screen import warm_up

    warm_up()  # once per worker process, as in a batch: not a trial's time
    return replication_trial_seconds(settings, placements)
