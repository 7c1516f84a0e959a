"""The race's runs into a directory (`playroom rl-race`): for each learner, grasp backend and
seed (race_settings.py `RaceRun`), the learner given the trial's movements and tested on the
held-out goals after every `eval_every` (race_learners.py); then every run's curve as one table,
the paired comparisons (race_claims.py), the record and the figure.

- SAC + HER (either settings): one policy on PlayroomToysGoal-v1 of the trial's grasp, world
  and voice, trained `eval_every` movements at a time (control_learner.py `sac_her`);
- Model Babbling: the trial itself (experiments/run/trial.py) in trials/GRASP-seedNNNN/, run
  to each budget in turn (a trial extended equals one run to the larger number from the start),
  its agent read back at each (`load_trial`) and tested, each test kept in
  trials/GRASP-seedNNNN-tests/ so that a stopped run resumes at its first budget not tested;
- random arm commands: the chance level on the same goals (control_learner.py `random_act`).

The directory: race.json (what every run shares; a directory of other settings is refused);
runs/NAME.csv and .json when a run ends (its curve; seconds, libraries, machine): a run done is
never redone, a stopped one starts again (Model Babbling's trial resumes from its checkpoint);
then rl-race.csv (learner, grasp, seed, steps, ring, goals, success), rl-race-claims.csv,
rl-race.png and rl-race.json last."""

from __future__ import annotations

import io
import multiprocessing
import os
import time
from collections.abc import Callable, Sequence
from concurrent.futures import ProcessPoolExecutor, as_completed
from pathlib import Path
from typing import Any

import pandas as pd

from experiments.baseline import control_learner as cl
from experiments.baseline import race_learners as rl
from experiments.baseline.control_run import opened_record
from experiments.baseline.control_settings import (
    RANDOM_COMMANDS_PER_GOAL,
    TORCH_THREADS,
    learner_values,
    library_defaults,
)
from experiments.baseline.race_claims import claims
from experiments.baseline.race_settings import (
    MODEL_BABBLING,
    RANDOM_COMMANDS,
    SAC_SETTINGS,
    RaceError,
    RaceRun,
)
from experiments.baseline.training import library_versions, rl_library
from experiments.trial_dir import provenance, storage
from experiments.trial_dir.lock import DirectoryLock, DirectoryLocked
from experiments.trial_dir.reading import open_for_reading

RACE_FILE = "race.json"
RUNS, TRIALS = "runs", "trials"
TABLE, CLAIMS, RECORD, FIGURE = "rl-race.csv", "rl-race-claims.csv", "rl-race.json", "rl-race.png"
COLUMNS = ["learner", "grasp", "seed", "steps", "ring", "goals", "success"]
ALL_RINGS = "all"


def ring_shares(tested: pd.DataFrame) -> list[tuple[str, int, float]]:
    """A test's share of goals reached, near, far and in all: (ring, goals, success) rows."""
    return [
        (str(ring), len(goals), float(goals["reached"].mean()))
        for ring, goals in (*tested.groupby("ring"), (ALL_RINGS, tested))
    ]


def curve_rows(run: RaceRun, steps: int, tested: pd.DataFrame) -> list[dict[str, Any]]:
    """A test's rows: the share of held-out goals reached, near, far and in all (`goals`: the
    movements tested, several a goal for random commands)."""
    own = {"learner": run.learner, "grasp": run.trial.grasp, "seed": run.trial.seed, "steps": steps}
    return [
        {**own, "ring": ring, "goals": goals, "success": success}
        for ring, goals, success in ring_shares(tested)
    ]


def _env(run: RaceRun, motor: str | None = None) -> Any:
    import gymnasium

    import sim.envs  # noqa: F401  (registers the ids)

    trial = run.trial
    return gymnasium.make(
        rl.toys_goal_id(trial.grasp), preset=trial.preset, voice=trial.voice, motor=motor
    )


def run_sac(run: RaceRun, threads: int = TORCH_THREADS) -> tuple[list[dict[str, Any]], float]:
    """SAC + HER's curve (the module's docstring), and the seconds its tests took."""
    env, test_env = _env(run), _env(run)
    model = cl.sac_her(env, run.trial.seed, threads, SAC_SETTINGS[run.learner])
    rows, testing = [], 0.0
    for budget in run.budgets():
        model.learn(budget - model.num_timesteps, reset_num_timesteps=False)
        start = time.perf_counter()
        tested = rl.tested_goals(cl.policy_act(model), test_env, run.test_seeds())
        testing += time.perf_counter() - start
        rows += curve_rows(run, budget, tested)
    env.close()
    test_env.close()
    return rows, testing


def run_random(run: RaceRun) -> tuple[list[dict[str, Any]], float]:
    """The chance level: random arm commands on the held-out goals, RANDOM_COMMANDS_PER_GOAL a
    goal from a generator of the run's seed, tested once (nothing learns) and written at every
    budget; and the seconds the test took."""
    env = _env(run)
    start = time.perf_counter()
    act = cl.random_act(env.action_space, run.trial.seed)
    tested = rl.tested_goals(act, env, run.test_seeds(), RANDOM_COMMANDS_PER_GOAL)
    testing = time.perf_counter() - start
    env.close()
    return [row for budget in run.budgets() for row in curve_rows(run, budget, tested)], testing


def run_model_babbling(run: RaceRun, trial_dir: Path) -> tuple[list[dict[str, Any]], float]:
    """Model Babbling's curve (the module's docstring), and the seconds its tests took."""
    from experiments.run.trial import run_trial
    from experiments.run.trial_parts import load_trial

    test_env = _env(run, motor="both")
    tests = trial_dir.with_name(f"{trial_dir.name}-tests")
    rows, testing = [], 0.0
    for budget in run.budgets():
        saved = tests / f"{budget:08d}.csv"
        if saved.is_file():  # tested before the run was stopped
            tested = pd.read_csv(saved)
        else:
            started = open_for_reading(trial_dir).has_config()
            run_trial(trial_dir, run.trial_at(budget), resume=started, progress=False)
            _, agent, _, meta = load_trial(trial_dir)
            assert meta["iteration"] == budget  # the agent of this budget, not a later one
            start = time.perf_counter()
            tested = rl.tested_goals(rl.model_babbling_act(agent), test_env, run.test_seeds())
            testing += time.perf_counter() - start
            storage.write_files(tests, {saved.name: tested.to_csv(index=False).encode()})
        rows += curve_rows(run, budget, tested)
    test_env.close()
    return rows, testing


def run_one(out: Path, run: RaceRun, threads: int = TORCH_THREADS) -> str:
    """One run, its curve and record written into out/runs/ when it ends; its name."""
    start = time.perf_counter()
    if run.learner == MODEL_BABBLING:
        trial_dir = out / TRIALS / f"{run.trial.grasp}-seed{run.trial.seed:04d}"
        rows, testing = run_model_babbling(run, trial_dir)
    elif run.learner == RANDOM_COMMANDS:
        rows, testing = run_random(run)
    else:
        rows, testing = run_sac(run, threads)
    record = {
        "learner": run.learner,
        "grasp": run.trial.grasp,
        "seed": run.trial.seed,
        "seconds": round(time.perf_counter() - start, 1),
        "test_seconds": round(testing, 1),  # of them, the held-out tests'
        "libraries": library_versions(),
        "computed_on": provenance.short_record(provenance.machine_record()),
    }
    table = pd.DataFrame(rows, columns=COLUMNS)
    storage.write_files(
        out / RUNS,
        {
            f"{run.name}.csv": table.to_csv(index=False).encode(),
            f"{run.name}.json": storage.json_bytes(record),
        },
    )
    return run.name


def run_race(
    out_dir: str | os.PathLike,
    runs: Sequence[RaceRun],
    command: str,
    figure: Callable[[pd.DataFrame], bytes],
    workers: int = 1,
    threads: int = TORCH_THREADS,
) -> Path:
    """Every run not yet done, side by side on `workers` processes, then the tables, record and
    figure of all (the module's docstring; `figure` draws it from the table); the table's path.
    RaceError (one line) before any work for a directory of other settings or one another
    process writes; naming every run that failed, after the others are done."""
    out = Path(out_dir)
    if not runs:
        raise RaceError("no run asked for: give at least one learner, grasp and seed")
    rl_library()  # the extra's absence said before anything is written
    try:
        storage.check_writable(out)
        lock = DirectoryLock(out).acquire()
    except DirectoryLocked as exc:
        raise RaceError(str(exc)) from None
    except OSError as exc:
        raise RaceError(f"cannot write into {out}: {storage.reason(exc)}") from None
    try:
        shared = _started(out, runs[0])
        for run in runs:
            if run.shared() != shared["settings"]:
                raise RaceError(
                    f"{out} holds a race of other settings: give another --out, or the "
                    "settings it has (race.json)"
                )
        left = [r for r in runs if not (out / RUNS / f"{r.name}.json").is_file()]
        failed = []
        # "spawn": each worker a fresh interpreter (torch and MuJoCo are not fork-safe).
        context = multiprocessing.get_context("spawn")
        with ProcessPoolExecutor(max(1, workers), mp_context=context) as pool:
            futures = {pool.submit(run_one, out, r, threads): r.name for r in left}
            for future in as_completed(futures):
                try:
                    print(f"playroom rl-race: {future.result()} done", flush=True)
                except Exception as exc:  # each failure named at the end, the others kept
                    failed.append(f"{futures[future]}: {exc}")
        if failed:
            raise RaceError(f"{len(failed)} of {len(left)} runs failed: " + "; ".join(failed))
        table = pd.concat([pd.read_csv(out / RUNS / f"{r.name}.csv") for r in runs])
        records = [storage.read_json(out / RUNS / f"{r.name}.json") for r in runs]
        text = io.StringIO()
        table.to_csv(text, index=False, float_format="%.4g")
        record = {**shared, "command": command, "runs": records}
        storage.write_files(
            out,
            {
                TABLE: text.getvalue().encode(),
                CLAIMS: claims(table).to_csv(index=False, float_format="%.4g").encode(),
                FIGURE: figure(table),
                RECORD: storage.json_bytes(storage.finite_or_null(record)),
            },
        )
        return out / TABLE
    finally:
        lock.release()


def _started(out: Path, first: RaceRun) -> dict:
    """race.json: written for a new directory, or read back."""

    def new() -> dict:
        return {
            "settings": first.shared(),
            "sac_her": learner_values(),
            "sac_her_defaults": library_defaults(),
        }

    return opened_record(out, RACE_FILE, "race", RaceError, new)
