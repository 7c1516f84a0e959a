"""The positive control's runs into a directory (`playroom rl-control`): for each goal and seed,
SAC + HER (control_learner.py) trained on the goal's environment (sim/envs, goal ids v1 with
their defaults: the arm alone, one movement an episode, the sparse reward), tested on the
held-out goals before it moves and every `eval_every` movements, beside the nearest outcome
among the movements it was given and random arm commands on the same goals; then the curves of
every run as one table, its record and its figure.

The directory:
- control.json: what every run of the directory shares (movements, tests, grasp), the learner's
  settings and stable-baselines3's defaults; a directory of other settings is refused;
- runs/GOAL-seedNNNN.csv and .json, written when a run ends (its curve; its seed, seconds,
  libraries and machine): a run done is never redone, one stopped starts again;
- rl-control.csv (goal, seed, learner, steps, success, critic_success, saturated: every run's
  rows), rl-control.json (control.json's record, each run's and the command) and
  rl-control.png (the curves), written after the last run, rl-control.json last.
"""

from __future__ import annotations

import io
import os
import time
from collections.abc import Callable, Iterable
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd
from tqdm import tqdm

from experiments.baseline import control_learner as cl
from experiments.baseline.control_settings import (
    CONTROL,
    FIRST_TEST_SEED,
    NEAREST,
    RANDOM,
    RANDOM_COMMANDS_PER_GOAL,
    TORCH_THREADS,
    ControlError,
    ControlSettings,
    learner_values,
    library_defaults,
)
from experiments.baseline.training import library_versions, rl_library
from experiments.trial_dir import provenance, storage
from experiments.trial_dir.lock import DirectoryLock, DirectoryLocked, holds_only_lock
from sim.envs.versions import GOAL_VARIANTS

CONTROL_FILE = "control.json"
RUNS = "runs"
TABLE, RECORD, FIGURE = "rl-control.csv", "rl-control.json", "rl-control.png"
COLUMNS = ["goal", "seed", "learner", "steps", "success", "critic_success", "saturated"]
# What a run's settings share with the directory's (the rest, goal and seed, name the run).
SHARED = ("movements", "eval_every", "eval_goals", "grasp", "settings", "test_goals")


def goal_id(goal: str, grasp: str) -> str:
    """The registered goal id of a goal and grasp backend (sim/envs/versions.py)."""
    (found,) = [
        name
        for name, kwargs in GOAL_VARIANTS.items()
        if kwargs["goal"] == goal and kwargs.get("grasp", "kinematic") == grasp
    ]
    return found


def run_one(
    settings: ControlSettings, threads: int = TORCH_THREADS, bar: tqdm | None = None
) -> tuple[pd.DataFrame, dict]:
    """One run (the module's docstring): its curve's rows and its record."""
    import gymnasium

    import sim.envs  # noqa: F401  (registers the ids)

    env_id = goal_id(settings.goal, settings.grasp)
    env, test_env = gymnasium.make(env_id), gymnasium.make(env_id)
    seeds = settings.test_seeds()
    model = cl.sac_her(env, settings.seed, threads, settings.settings)
    start = time.perf_counter()
    rows: list[dict[str, Any]] = []
    space = test_env.action_space
    assert isinstance(space, gymnasium.spaces.Box)  # a goal environment's motor space
    chance = cl.tested(
        cl.random_act(space, settings.seed), test_env, seeds, RANDOM_COMMANDS_PER_GOAL
    )
    for steps in settings.checkpoints():
        if steps > model.num_timesteps:
            model.learn(steps - model.num_timesteps, reset_num_timesteps=False)
            if bar is not None:
                bar.update(settings.eval_every)
        policy = cl.tested(cl.policy_act(model), test_env, seeds)
        critic = cl.critic_view(model, policy)
        rows.append(_row(settings, settings.learner, steps, policy.success, critic))
        if steps > 0:  # the nearest outcome needs movements to look among
            nearest = cl.tested(cl.nearest_outcome_act(model), test_env, seeds)
            rows.append(_row(settings, NEAREST, steps, nearest.success))
        rows.append(_row(settings, RANDOM, steps, chance.success))
    record = {
        "settings": settings.record(),
        "env_id": env_id,
        "seconds": round(time.perf_counter() - start, 1),
        "libraries": library_versions(),
        "computed_on": provenance.short_record(provenance.machine_record()),
    }
    env.close()
    test_env.close()
    return pd.DataFrame(rows, columns=COLUMNS), record


def _row(
    settings: ControlSettings,
    learner: str,
    steps: int,
    success: float,
    critic: dict[str, float] | None = None,
) -> dict[str, Any]:
    critic = critic or {}
    return {
        "goal": settings.goal,
        "seed": settings.seed,
        "learner": learner,
        "steps": steps,
        "success": success,
        "critic_success": critic.get("critic_success", np.nan),
        "saturated": critic.get("saturated", np.nan),
    }


def run_control(
    out_dir: str | os.PathLike,
    runs: Iterable[ControlSettings],
    command: str,
    figure: Callable[[pd.DataFrame], bytes],
    threads: int = TORCH_THREADS,
    progress: bool = False,
    notify: Callable[[str], None] | None = None,
) -> Path:
    """Every run not yet done, then the table, record and figure of all (the module's
    docstring); the table's path. ControlError (one line) before any work for a directory of
    other settings or one being written by another process."""
    out = Path(out_dir)
    runs = list(runs)
    if not runs:
        raise ControlError("no run asked for: give at least one goal and one seed")
    rl_library()  # the extra's absence said before anything is written
    try:
        storage.check_writable(out)
        lock = DirectoryLock(out).acquire()
    except DirectoryLocked as exc:
        raise ControlError(str(exc)) from None
    except OSError as exc:
        raise ControlError(f"cannot write into {out}: {storage.reason(exc)}") from None
    try:
        shared = _started(out, runs[0])
        for settings in runs:
            asked = {k: settings.record()[k] for k in SHARED}
            if asked != shared["settings"]:
                differ = [
                    f"{k} {shared['settings'].get(k)!r} (asked {v!r})"
                    for k, v in asked.items()
                    if shared["settings"].get(k) != v
                ]
                raise ControlError(
                    f"{out} holds runs of other settings ({', '.join(differ)}): give another "
                    "--out, or the settings it has"
                )
        left = [s for s in runs if not (out / RUNS / f"{s.name}.json").is_file()]
        if notify is not None and len(left) < len(runs):
            notify(f"{len(runs) - len(left)} of the {len(runs)} runs are done in {out}")
        total = sum(s.movements for s in left)
        with tqdm(total=total, disable=not progress or not left, unit="movement") as bar:
            for settings in left:
                bar.set_description(settings.name)
                table, record = run_one(settings, threads, bar)
                storage.write_files(
                    out / RUNS,
                    {
                        f"{settings.name}.csv": table.to_csv(index=False).encode(),
                        f"{settings.name}.json": storage.json_bytes(record),
                    },
                )
        return _written(out, runs, shared, command, figure)
    finally:
        lock.release()


def opened_record(
    out: Path, name: str, what: str, error: type[Exception], new: Callable[[], dict]
) -> dict:
    """The record `name` of a run directory (`what` it holds) read back, or `new()` written
    into a new one; `error` (one line) for a damaged record or a directory holding another
    thing. Shared by the control and the race."""
    path = out / name
    if path.exists():
        try:
            record = storage.read_json(path)
            record["settings"]  # noqa: B018  (a record without it is damaged)
        except (storage.CorruptFileError, KeyError, TypeError):
            raise error(f"{path} is damaged: remove {out} to run it again") from None
        return record
    if out.exists() and not holds_only_lock(out):
        raise error(f"{out} is not empty and holds no {what}: give another --out")
    record = new()
    storage.write_json(path, record)
    return record


def _started(out: Path, first: ControlSettings) -> dict:
    """control.json: written for a new directory, or read back."""

    def new() -> dict:
        defaults = library_defaults()
        return {
            "settings": {k: first.record()[k] for k in SHARED},
            "test_goals": {
                "first_reset_seed": FIRST_TEST_SEED[first.test_goals],
                "random_commands_per_goal": RANDOM_COMMANDS_PER_GOAL,
            },
            "learner": learner_values() if first.settings == CONTROL else defaults,
            "stable_baselines3_defaults": defaults,
        }

    return opened_record(out, CONTROL_FILE, "control", ControlError, new)


def _written(
    out: Path,
    runs: list[ControlSettings],
    shared: dict,
    command: str,
    figure: Callable[[pd.DataFrame], bytes],
) -> Path:
    tables = [pd.read_csv(out / RUNS / f"{s.name}.csv") for s in runs]
    records = [storage.read_json(out / RUNS / f"{s.name}.json") for s in runs]
    table = pd.concat(tables, ignore_index=True)
    text = io.StringIO()
    table.to_csv(text, index=False, float_format="%.4g")
    record = {**shared, "command": command, "runs": records}
    storage.write_files(
        out,
        {
            TABLE: text.getvalue().encode(),
            FIGURE: figure(table),
            RECORD: storage.json_bytes(storage.finite_or_null(record)),
        },
    )
    return out / TABLE
