"""How much of Model Babbling's race score is the question it is asked: every Model Babbling
trial of a finished race tested again on the race's held-out goals, its memory looked up by
where the toy starts and ends instead of by the study's straight goal trajectory.

The race asks Model Babbling as the project's measure does (race_learners.py): the toy's
straight way from where it lies to the point, sampled at the measure's times, against each
stored trajectory, nearest in (context, trajectory). A toy moved by the hand lies still until
the hand reaches it, so no stored trajectory is straight; the environment scores only the end.
The lookup here asks the same memory the question the environment scores: the toy's arm
experience whose context, first and last sampled positions are together nearest (the sum of
their squared distances) to the scene's context, where the toy lies and the desired point; its
command is replayed as it was. It is not a learner of its own: an upper reference for what a
nearest-neighbour question put to that memory can get, beside the race's own."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from experiments.baseline import race_learners as rl
from experiments.baseline.race_claims import paired_p
from experiments.baseline.race_run import TRIALS, ring_shares
from experiments.baseline.race_settings import FIRST_HELD_OUT_SEED, RaceError
from experiments.trial_dir import storage
from learner.agent import Agent
from models.layout import CONTEXT_DIM, N_SAMPLES
from sim.envs.gym_env import ACTION_DIM, ARM_PART, SELECTOR, SPACE_DTYPE
from sim.envs.motor_spaces import SWITCH
from sim.envs.toys_goal_env import POSITION_PART, TOY_PART

LOOKUP_TABLE, LOOKUP_SUMMARY = "rl-race-lookup.csv", "rl-race-lookup-summary.csv"
STRAIGHT, START_END = "straight-trajectory", "start-end-lookup"
LOOKUP_COLUMNS = ["grasp", "seed", "steps", "question", "ring", "goals", "success"]
# A trial's directory in the race's trials/: GRASP-seedNNNN (its tests beside it, -tests).
TESTS_SUFFIX = "-tests"


def start_end_lookup_act(agent: Agent) -> rl.Act:
    """The arm command of the toy's stored experience nearest in context, start and end (the
    module's docstring); the arm at rest where the toy's arm model holds nothing."""

    def act(observation: rl.DictObs) -> np.ndarray:
        desired, lies = observation["desired_goal"], observation["achieved_goal"]
        toy = int(np.argmax(desired[TOY_PART])) + 1
        model = agent.models[agent.toy_models(toy)[0]]
        action = np.zeros(ACTION_DIM, dtype=SPACE_DTYPE)
        action[SELECTOR] = SWITCH["arm"]
        if len(model) == 0:
            return action
        context = np.asarray(observation["observation"][:CONTEXT_DIM], dtype=np.float64)
        sensory = model.sensory  # 5 x, then 5 y
        start = sensory[:, [0, N_SAMPLES]]
        end = sensory[:, [N_SAMPLES - 1, 2 * N_SAMPLES - 1]]
        distance = (
            ((model.context - context[model.context_dims]) ** 2).sum(axis=1)
            + ((start - lies[POSITION_PART]) ** 2).sum(axis=1)
            + ((end - desired[POSITION_PART]) ** 2).sum(axis=1)
        )
        action[ARM_PART] = model.motor[int(np.argmin(distance))]
        return action

    return act


def _rows(grasp: str, seed: int, steps: int, question: str, tested: pd.DataFrame) -> list[dict]:
    own = (grasp, seed, steps, question)
    return [dict(zip(LOOKUP_COLUMNS, (*own, *share), strict=True)) for share in ring_shares(tested)]


def race_lookup(race_dir: str | Path) -> pd.DataFrame:
    """Every Model Babbling trial of `race_dir` at its final budget, asked both ways on the
    race's held-out goals (the straight question's answers read back from the race's own test
    of that budget); written to race_dir/LOOKUP_TABLE and returned. RaceError (one line) for a
    directory without a race or with a trial not run to its end."""
    import gymnasium

    import sim.envs  # noqa: F401  (registers the ids)
    from experiments.run.trial_parts import load_trial

    race = Path(race_dir)
    if not (race / "race.json").is_file():
        raise RaceError(f"{race} holds no race (race.json is missing): run playroom rl-race")
    settings = storage.read_json(race / "race.json")["settings"]
    trial, iterations = settings["trial"], settings["trial"]["iterations"]
    seeds = range(FIRST_HELD_OUT_SEED, FIRST_HELD_OUT_SEED + settings["eval_goals"])
    trial_dirs = sorted(
        d for d in (race / TRIALS).glob("*-seed*") if not d.name.endswith(TESTS_SUFFIX)
    )
    if not trial_dirs:
        raise RaceError(f"{race} has no Model Babbling trial yet")
    rows = []
    for trial_dir in trial_dirs:
        grasp, seed = trial_dir.name.rsplit("-seed", 1)
        saved = trial_dir.with_name(trial_dir.name + TESTS_SUFFIX) / f"{iterations:08d}.csv"
        if not saved.is_file():
            raise RaceError(f"{trial_dir} is not tested at {iterations} yet: finish the race")
        _, agent, _, meta = load_trial(trial_dir)
        if meta["iteration"] != iterations:
            raise RaceError(f"{trial_dir} stands at {meta['iteration']}, not {iterations}")
        env = gymnasium.make(
            rl.toys_goal_id(grasp), preset=trial["preset"], voice=trial["voice"], motor="both"
        )
        looked_up = rl.tested_goals(start_end_lookup_act(agent), env, seeds)
        env.close()
        for question, tested in ((STRAIGHT, pd.read_csv(saved)), (START_END, looked_up)):
            rows += _rows(grasp, int(seed), iterations, question, tested)
    table = pd.DataFrame(rows, columns=LOOKUP_COLUMNS)
    storage.write_files(
        race,
        {
            LOOKUP_TABLE: table.to_csv(index=False, float_format="%.4g").encode(),
            LOOKUP_SUMMARY: lookup_summary(table).to_csv(index=False, float_format="%.4g").encode(),
        },
    )
    return table


def lookup_summary(table: pd.DataFrame) -> pd.DataFrame:
    """Per grasp backend (and both together: "both") and ring, the mean success of each question
    over the trials, the lookup's less the straight one's, and the two-sided Wilcoxon
    signed-rank p over the trials' differences (race_claims.py's paired_p)."""
    wide = table.pivot_table(
        index=["grasp", "seed", "ring"], columns="question", values="success"
    ).reset_index()
    rows = []
    for grasp in [*sorted(wide["grasp"].unique()), "both"]:
        part = wide if grasp == "both" else wide[wide["grasp"] == grasp]
        for ring, one in part.groupby("ring"):
            difference = (one[START_END] - one[STRAIGHT]).to_numpy()
            rows.append([grasp, ring, len(one), one[STRAIGHT].mean(), one[START_END].mean(),
                         difference.mean(), paired_p(difference)])  # fmt: skip
    columns = ["grasp", "ring", "trials", STRAIGHT, START_END, "difference", "p_value"]
    return pd.DataFrame(rows, columns=columns)
