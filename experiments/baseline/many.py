"""The baselines of a batch config (experiments/batches/spec.py's JSON form, as `playroom batch
--config` reads it): for every trial the batch would run, a baseline of the same grasp, seed,
world and number of movements (its iterations), evaluated on the batch's placements, each into
`OUT/<grasp>-sac-her-seedNNNN/`, side by side on worker processes. Finished runs are skipped and
stopped ones resume (run.py), so that rerunning the same command goes on where it stopped."""

from __future__ import annotations

import multiprocessing
import os
from concurrent.futures import ProcessPoolExecutor, as_completed
from pathlib import Path

from tqdm import tqdm

from experiments.baseline.run import is_finished, run_baseline
from experiments.baseline.settings import (
    TORCH_THREADS,
    BaselineError,
    BaselineSettings,
    run_name,
)
from experiments.baseline.training import rl_library
from experiments.batches.spec import BatchError, load_spec


def batch_baselines(
    config_file: str | os.PathLike, torch_threads: int = TORCH_THREADS
) -> list[BaselineSettings]:
    """The baseline of each trial of a batch config; BaselineError (one line) for a config that
    is refused or that asks for more than the baseline has (several babbling modes are one
    baseline; eval worlds have no baseline counterpart yet)."""
    try:
        spec = load_spec(config_file=config_file)
    except BatchError as exc:
        raise BaselineError(str(exc)) from None
    if spec.eval_worlds:
        raise BaselineError(
            f"{config_file}: eval_worlds have no baseline counterpart: leave them out"
        )
    runs = {}
    for _, trial in spec.trials():
        settings = BaselineSettings(
            steps=trial.iterations,
            grasp=trial.grasp,
            seed=trial.seed,
            preset=trial.preset,
            voice=trial.voice,
            overrides=trial.overrides,
            eval_placements=spec.eval_placements,
            torch_threads=torch_threads,
        )
        runs[run_name(settings)] = settings  # one per grasp and seed, whatever the babbling
    return list(runs.values())


def _one(out: str, settings: BaselineSettings, command: str) -> str:
    run_baseline(out, settings, command)
    return out


def run_batch_baselines(
    config_file: str | os.PathLike,
    out_dir: str | os.PathLike,
    command: str,
    workers: int | None = None,
    progress: bool = False,
    torch_threads: int = TORCH_THREADS,
) -> tuple[int, int]:
    """Every baseline of the config into `out_dir` on `workers` processes (default: the cores);
    (runs done now, runs found finished). BaselineError naming each run that failed, after the
    others are done."""
    runs = batch_baselines(config_file, torch_threads)
    rl_library()
    out = Path(out_dir)
    todo = [(str(out / run_name(s)), s) for s in runs if not is_finished(out / run_name(s))]
    failed = []
    # "spawn": each worker a fresh interpreter (torch and MuJoCo are not fork-safe).
    context = multiprocessing.get_context("spawn")
    with (
        ProcessPoolExecutor(workers or os.cpu_count(), mp_context=context) as pool,
        tqdm(total=len(todo), disable=not progress, desc="baselines", unit="run") as bar,
    ):
        futures = {pool.submit(_one, path, s, command): path for path, s in todo}
        for future in as_completed(futures):
            try:
                future.result()
            except BaselineError as exc:
                failed.append(f"{Path(futures[future]).name}: {exc}")
            bar.update(1)
    if failed:
        raise BaselineError(f"{len(failed)} of {len(todo)} baselines failed: " + "; ".join(failed))
    return len(todo), len(runs) - len(todo)
