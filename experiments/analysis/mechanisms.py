"""What a trial's logs say about why two conditions differ (issue 32): per-trial numbers of
where the agent's exploration went, what it heard and what the caregiver understood.

From the iterations log (experiments/analysis/logs.py) and the trial's names:
- model_share_k (k = 1..10, docs/protocol.md's models): the share of goal-babbling iterations
  (after the random bootstrap) whose goal was in model k's space: where interest sent it;
- heard_per_name, heard_per_distractor: how often the caregiver said each name (a toy in the
  hand at the end of an arm movement) and each distractor (nothing in the hand), per word;
- imitation_goals_names, imitation_goals_distractors: model 10's goals that were one of the
  caregiver's words (imitation), per word of each kind; random_sound_goals: its other goals;
- recognised_names, recognised_distractors: vocal movements the caregiver understood as a
  name (she then brings its toy) or as a distractor;
- name_recognised_after_toy_goal: the share of vocal movements with a toy goal (models 7-9)
  that made the caregiver bring a toy: the social tool working;
- first_name_recognised: the first iteration at which a name was understood (NaN: never);
- toy_held, toy_pushed, stick_held, stick_pushed per 1000 arm movements: how arm movements
  moved things.

An imitation goal is recognised without the voice's word table: the caregiver's sound after an
arm movement is the word's exact features, which is what model 6 (arm -> sound) reaches, so
the goals of model 10 equal to one of those vectors are imitations of that word.
"""

from __future__ import annotations

import math

import numpy as np
import pandas as pd

from experiments.log_schema import GOAL_COLUMNS, REACHED_COLUMNS
from models.layout import MODELS, TOYS

# The iterations log's columns `trial_mechanisms` reads beyond experiments/analysis/curves.py's.
LOG_COLUMNS = (
    "iteration",
    "motor_space",
    "model",
    "caregiver_said",
    "word_recognised",
    "stick_grasped",
    "stick_moved_by",
    *(f"{toy}_moved_by" for toy in TOYS),
    *GOAL_COLUMNS,
    *REACHED_COLUMNS,
)
# Model numbers (1-based, as the paper numbers them) of the sound models and the voice's toys.
ARM_SOUND_MODEL = next(
    m.number for m in MODELS if m.motor_space == "arm" and m.sensory_block == "sound"
)
VOICE_SOUND_MODEL = next(m.number for m in MODELS if m.imitates_caregiver)
VOICE_TOY_MODELS = tuple(
    m.number for m in MODELS if m.motor_space == "voice" and m.sensory_block in TOYS
)


def word_sounds(log: pd.DataFrame) -> dict[str, np.ndarray]:
    """word -> its (10,) sound features, read off model 6's outcomes after the caregiver said
    it (module docstring); only the words said after a model-6 movement."""
    rows = log[(log["model"] == ARM_SOUND_MODEL - 1) & (log["caregiver_said"] != "")]
    first = rows.drop_duplicates("caregiver_said")
    return {
        str(r["caregiver_said"]): np.asarray([r[c] for c in REACHED_COLUMNS], dtype=np.float32)
        for _, r in first.iterrows()
    }


def _per_word(counts: pd.Series, words: set[str]) -> float:
    return float(sum(int(counts.get(w, 0)) for w in words) / len(words)) if words else math.nan


def trial_mechanisms(log: pd.DataFrame, names: set[str], words: set[str]) -> dict[str, float]:
    """The module docstring's numbers for one trial; `names` its toy names, `words` all six.
    All NaN for a log written before it held every column read here."""
    if not set(LOG_COLUMNS) <= set(log.columns):
        return dict.fromkeys(LABELS, math.nan)
    distractors = words - names
    chosen = log[log["model"] >= 0]
    out: dict[str, float] = {}
    shares = chosen["model"].value_counts(normalize=True)
    for model in MODELS:
        out[f"model_share_{model.number}"] = float(shares.get(model.number - 1, 0.0))
    arm = log[log["motor_space"] == "arm"]
    said = arm["caregiver_said"].value_counts()
    out["heard_per_name"] = _per_word(said, names)
    out["heard_per_distractor"] = _per_word(said, distractors)
    sound_goals = chosen[chosen["model"] == VOICE_SOUND_MODEL - 1]
    goals = sound_goals[list(GOAL_COLUMNS)].to_numpy(dtype=np.float32)
    imitated = pd.Series("", index=sound_goals.index)
    for word, features in word_sounds(log).items():
        imitated[(goals == features).all(axis=1)] = word
    counts = imitated.value_counts()
    out["imitation_goals_per_name"] = _per_word(counts, names)
    out["imitation_goals_per_distractor"] = _per_word(counts, distractors)
    out["random_sound_goals"] = float((imitated == "").sum())
    recognised = log["word_recognised"].value_counts()
    out["recognised_names"] = float(sum(int(recognised.get(w, 0)) for w in names))
    out["recognised_distractors"] = float(sum(int(recognised.get(w, 0)) for w in distractors))
    toy_goals = chosen[chosen["model"].isin([m - 1 for m in VOICE_TOY_MODELS])]
    out["name_recognised_after_toy_goal"] = (
        float(toy_goals["word_recognised"].isin(names).mean()) if len(toy_goals) else math.nan
    )
    understood = log.loc[log["word_recognised"].isin(names), "iteration"]
    out["first_name_recognised"] = float(understood.min()) if len(understood) else math.nan
    per_1000 = 1000.0 / max(1, len(arm))
    moved = arm[[f"{toy}_moved_by" for toy in TOYS]]
    out["toy_held"] = float((moved == "hand").any(axis=1).sum() * per_1000)
    out["toy_pushed"] = float((moved == "push").any(axis=1).sum() * per_1000)
    out["stick_held"] = float(arm["stick_grasped"].astype(bool).sum() * per_1000)
    out["stick_pushed"] = float((arm["stick_moved_by"] == "push").sum() * per_1000)
    return out


# Every number `trial_mechanisms` gives, in the order tables show them, with its label.
LABELS = {
    **{
        f"model_share_{m.number}": (
            f"Goals in model {m.number} ({m.motor_space} → {m.sensory_block})"
        )
        for m in MODELS
    },
    "heard_per_name": "Times the caregiver said each name",
    "heard_per_distractor": "Times the caregiver said each distractor",
    "imitation_goals_per_name": "Imitation goals per name (model 10)",
    "imitation_goals_per_distractor": "Imitation goals per distractor (model 10)",
    "random_sound_goals": "Self-generated sound goals (model 10)",
    "recognised_names": "Vocal movements understood as a name",
    "recognised_distractors": "Vocal movements understood as a distractor",
    "name_recognised_after_toy_goal": "Vocal toy goals (models 7-9) that made her bring a toy",
    "first_name_recognised": "First iteration a name was understood",
    "toy_held": "Arm movements holding a toy, per 1000",
    "toy_pushed": "Arm movements pushing a toy, per 1000",
    "stick_held": "Arm movements taking the stick, per 1000",
    "stick_pushed": "Arm movements pushing the stick, per 1000",
}
