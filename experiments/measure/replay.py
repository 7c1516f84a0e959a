"""Does a remembered movement repeat its outcome? A test of why a backend's competence within
the hand's reach can fall to the random level.

The agent chooses a movement by its memory: the arm model's nearest experience to (context,
goal) is a command m it made in a remembered context c, with a remembered outcome s. If m, redone
now, moved the goal toy as it did then, the error would be about that nearest distance; the
project's measure finds it larger. For each of ring 1's tests where the agent chose the arm
(the placements, caregivers and stick start of `competence_table`), m is replayed in three
scenes and the goal toy's outcome compared with s (its distance to s, 0 when it repeats):
- "test": the test's own scene, as the evaluation plays it;
- "stick_at_start": the test's scene with the goal toy where the experience had it: what the
  stick's own shift (to its start place, where every test puts it) leaves;
- "remembered": the stick's handle and the goal toy where the experience had them (the stick
  at its start angle: a context holds no angle), the other toys as in the test;
- "alone": the remembered scene with the other toys far out of every reach.
If the movement repeats in "alone" but not in "test", the outcome depends on what the model's
context does not hold (the other toys, the stick's angle); if it does not repeat even alone, on
small differences of the context itself (the sensitivity of contacts).

`playroom replay BATCH_DIR --trials N --out FILE.csv [--figure FILE.png]` writes one row per
(trial, test) and prints the medians and means per backend
(experiments/cli/agent_measures_command.py).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from experiments.measure.evaluation import (
    EvaluationSettings,
    goal_trajectory,
    scene_placements,
)
from experiments.run.trial_parts import fresh_trial_parts
from experiments.trial_dir.errors import TrialError
from experiments.trial_dir.reading import EVALUATION_MARK, SCENES_KEY, open_for_reading
from learner.agent import Agent
from models.layout import TOYS, block_slice
from sim import Playroom
from sim.grasping.names import GRASPS

SCENES = ("test", "stick_at_start", "remembered", "alone")
# Where the other toys wait in the "alone" scene: beyond ring 3 and every reach, on the table.
FAR_AWAY = np.array([[1.2, 0.0], [-1.2, 0.0], [0.0, -1.2]])


def replay_table(agent: Agent, room: Playroom, settings: EvaluationSettings) -> pd.DataFrame:
    """One row per arm test of ring 1: toy, the nearest distance the agent chose by, and per
    scene the outcome's distance to the remembered outcome and to the goal (columns
    repeat_<scene>, error_<scene>). Ring 1 only: its placements and caregivers are the
    evaluation's first draws, so its scenes are the evaluation's own."""
    rng = np.random.default_rng(settings.seed)
    stick_start = (*room.config.stick_start_handle, room.config.stick_start_angle)
    rows = []
    toys_of = scene_placements(room, room.config.toy_rings[0], settings, rng)
    caregivers = rng.uniform(-1, 1, (settings.n_placements, 2))
    for p in range(settings.n_placements):
        room.arrange(stick=stick_start, toys=toys_of[p], caregiver=caregivers[p])
        scene = room.get_state()
        context = room.context()
        for t, toy in enumerate(TOYS):
            goal = goal_trajectory(toys_of[p, t])
            arm_model, voice_model = agent.toy_models(t + 1)
            d_arm = agent.nearest_distance(arm_model, context, goal)
            if not np.isfinite(d_arm) or d_arm > agent.nearest_distance(voice_model, context, goal):
                continue  # the voice's test, or an untrained arm
            m, remembered, outcome, _ = agent.models[arm_model].nearest_experience(context, goal)
            row = {
                "placement": p,
                "toy": t + 1,
                "expected": d_arm,
                # how far the test's context lies from the remembered one (m)
                "stick_shift": float(np.linalg.norm(context[:2] - remembered[:2])),
                "toy_shift": float(np.linalg.norm(toys_of[p, t] - remembered[2:4])),
            }
            for name in SCENES:
                room.set_state(scene)
                if name != "test":
                    toys = FAR_AWAY.copy() if name == "alone" else toys_of[p].copy()
                    toys[t] = remembered[2:4]  # the arm toy model's context: stick, toy
                    stick = stick_start if name == "stick_at_start" else remembered[:2]
                    room.arrange(stick=(stick[0], stick[1], stick_start[2]), toys=toys)
                s = room.act("arm", m).s[block_slice(toy)]
                row[f"repeat_{name}"] = float(np.linalg.norm(s - outcome))
                row[f"error_{name}"] = float(np.linalg.norm(s - goal))
            room.set_state(scene)
            rows.append(row)
    return pd.DataFrame(rows)


def replay_batch(batch_dir: Path, n_trials: int) -> pd.DataFrame:
    """`replay_table` of the first `n_trials` finished trials of each backend of a batch."""
    tables = []
    for grasp in GRASPS:
        trials = [open_for_reading(d) for d in sorted(batch_dir.glob(f"{grasp}-*"))]
        for trial in [t for t in trials if t.evaluation().exists()][:n_trials]:
            trial_dir = trial.dir
            config, agent, room, _ = trial.restored(fresh_trial_parts)
            evaluation = trial.evaluation()
            summary = evaluation.summary(config)
            # The evaluation's scenes (its placements), and the random command it played on
            # each of them beside the replays.
            settings = EvaluationSettings(
                int(summary["n_placements"]),
                scenes_clear_of_stick=bool(summary.get(SCENES_KEY, False)),
            )
            table = replay_table(agent, room, settings)
            if table.empty:  # no arm test chosen by a model (an untrained agent)
                continue
            evaluated = evaluation.required_table("competence", summary)
            random = evaluated[evaluated["ring"] == 1][["placement", "toy", "random_error"]]
            table = table.merge(random, on=["placement", "toy"], how="left")
            tables.append(table.assign(trial=trial_dir.name, grasp=grasp))
    if not tables:
        raise TrialError(
            f"{batch_dir} holds no finished trial whose agent chose an arm movement in ring 1 "
            f"(a trial folder with {EVALUATION_MARK}, past its random bootstrap)"
        )
    return pd.concat(tables, ignore_index=True)


def summaries(table: pd.DataFrame) -> tuple[str, str]:
    """The replay table's medians and means per backend, as text."""
    columns = [
        "expected",
        "random_error",
        "stick_shift",
        "toy_shift",
        *(f"{k}_{s}" for k in ("repeat", "error") for s in SCENES),
    ]
    by_grasp = table.groupby("grasp")[columns]
    return by_grasp.median().round(3).to_string(), by_grasp.mean().round(3).to_string()
