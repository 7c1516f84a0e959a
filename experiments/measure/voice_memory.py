"""What the voice's toy models remember: the evidence behind the voice learning worse with
contact grasping.

The agent's models 7-9 map a vocal command to a toy's trajectory; they store a movement only
when its toy moved (the storing rule). Under the kinematic rules a toy moves during a vocal
movement only when the caregiver brings it, i.e. when the command said the toy's name, so
every stored command is the name. In the physical room a toy can also move during a vocal
movement for a reason that has nothing to do with the voice (objects left overlapping by the
previous arm movement, a released stick lying across a toy, separate on the next movement's
first steps): the command stored then is whatever the agent said. A vocal toy goal whose
nearest experience is such a row replays a sound the caregiver does not understand.

For each voice -> toy model of a trial's final agent: how many rows it holds, and the share of
their commands that the caregiver recognises as that toy's name, as another word, or as no
word (the voice's own recognition, the caregiver's rule), and the share of rows whose toy
moved less than 2 cm from the first sample to the last (a nudge, not a bring).

`playroom voice-memory TRIAL_DIR [TRIAL_DIR ...] --out FILE.csv`
(experiments/cli/agent_measures_command.py).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from experiments.run.trial_parts import load_trial
from learner.agent import Agent
from sim import Playroom

# A toy brought by the caregiver travels tens of centimetres; below this it was nudged (m).
NUDGE = 0.02


def toy_model_rows(agent: Agent, room: Playroom) -> pd.DataFrame:
    """One row per toy: rows stored in its voice model, shares of their commands recognised
    as its name / another word / no word, share of nudges."""
    tract, names = room.vocal_tract, room.caregiver.words.names
    out = []
    for toy in (1, 2, 3):
        _, voice_model = agent.toy_models(toy)
        model = agent.models[voice_model]
        heard = [tract.recognise(tract.sound_features(m)) for m in np.asarray(model.motor)]
        s = np.asarray(model.sensory)  # 5 x then 5 y of the toy
        travel = np.hypot(s[:, 4] - s[:, 0], s[:, 9] - s[:, 5]) if len(s) else np.zeros(0)
        n = len(heard)

        def share(flags: list[bool] | np.ndarray, n: int = n) -> float:
            return float(np.mean(flags)) if n else float("nan")

        out.append(
            {
                "toy": toy,
                "rows": n,
                "name": share([w == names[toy - 1] for w in heard]),
                "other_word": share([w is not None and w != names[toy - 1] for w in heard]),
                "no_word": share([w is None for w in heard]),
                "nudged": share(travel < NUDGE),
            }
        )
    return pd.DataFrame(out)


def trials_table(trial_dirs: list[Path]) -> pd.DataFrame:
    """`toy_model_rows` of each trial's final agent, labelled with its trial and grasp;
    TrialError (experiments/trial_dir/errors.py) for a directory that holds no readable
    trial."""
    tables = []
    for trial_dir in trial_dirs:
        config, agent, room, _ = load_trial(trial_dir)
        table = toy_model_rows(agent, room)
        tables.append(table.assign(trial=trial_dir.name, grasp=config["trial"]["grasp"]))
    return pd.concat(tables, ignore_index=True)
