"""What a trial's logs say about why two conditions differ: per-trial numbers of
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
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
import pandas as pd

from experiments.trial_dir.log_schema import (
    CAREGIVER_SAID,
    GOAL_COLUMNS,
    ITERATION,
    MODEL,
    MOTOR_SPACE,
    REACHED_COLUMNS,
    STICK_GRASPED,
    STICK_MOVED_BY,
    TOY_MOVED_BY,
    WORD_RECOGNISED,
    recorded,
)
from models.layout import MODELS, TOYS

# Model numbers (1-based, as the paper numbers them) of the sound models and the voice's toys.
ARM_SOUND_MODEL = next(
    m.number for m in MODELS if m.motor_space == "arm" and m.sensory_block == "sound"
)
VOICE_SOUND_MODEL = next(m.number for m in MODELS if m.imitates_caregiver)
VOICE_TOY_MODELS = tuple(
    m.number for m in MODELS if m.motor_space == "voice" and m.sensory_block in TOYS
)


def _words_heard_through_model_6(log: pd.DataFrame) -> pd.DataFrame:
    return log[(log[MODEL] == ARM_SOUND_MODEL - 1) & (log[CAREGIVER_SAID] != "")]


def word_sounds(log: pd.DataFrame) -> dict[str, np.ndarray]:
    """word -> its (10,) sound features, read off model 6's outcomes after the caregiver said
    it (module docstring); only the words said after a model-6 movement."""
    first = _words_heard_through_model_6(log).drop_duplicates(CAREGIVER_SAID)
    return {
        str(r[CAREGIVER_SAID]): np.asarray([r[c] for c in REACHED_COLUMNS], dtype=np.float32)
        for _, r in first.iterrows()
    }


def _per_word(counts: pd.Series, words: set[str]) -> float:
    return float(sum(int(counts.get(w, 0)) for w in words) / len(words)) if words else math.nan


def _chosen(log: pd.DataFrame) -> pd.DataFrame:
    """The goal-babbling iterations: a model was chosen (after the random bootstrap)."""
    return log[log[MODEL] >= 0]


def _shares(log: pd.DataFrame, names: set[str], distractors: set[str]) -> dict[str, float]:
    shares = _chosen(log)[MODEL].value_counts(normalize=True)
    return {f"model_share_{m.number}": float(shares.get(m.number - 1, 0.0)) for m in MODELS}


def _heard(log: pd.DataFrame, names: set[str], distractors: set[str]) -> dict[str, float]:
    said = log.loc[log[MOTOR_SPACE] == "arm", CAREGIVER_SAID].value_counts()
    return {
        "heard_per_name": _per_word(said, names),
        "heard_per_distractor": _per_word(said, distractors),
    }


def _sound_goals(log: pd.DataFrame) -> pd.DataFrame:
    return log[log[MODEL] == VOICE_SOUND_MODEL - 1]


def _imitation(log: pd.DataFrame, names: set[str], distractors: set[str]) -> dict[str, float]:
    sound_goals = _sound_goals(log)
    goals = sound_goals[list(GOAL_COLUMNS)].to_numpy(dtype=np.float32)
    imitated = pd.Series("", index=sound_goals.index)
    for word, features in word_sounds(log).items():
        imitated[(goals == features).all(axis=1)] = word
    counts = imitated.value_counts()
    return {
        "imitation_goals_per_name": _per_word(counts, names),
        "imitation_goals_per_distractor": _per_word(counts, distractors),
        "random_sound_goals": float((imitated == "").sum()),
    }


def _goals_recorded(log: pd.DataFrame) -> bool:
    """Whether the log holds what the imitation numbers read: model 10's goals, and model 6's
    outcomes where the caregiver spoke after it (NaN there: a trial written before goals and
    outcomes were logged; elsewhere NaN is the bootstrap's, which has neither)."""
    return (
        recorded(log, (MODEL, CAREGIVER_SAID))
        and set(GOAL_COLUMNS) | set(REACHED_COLUMNS) <= set(log.columns)
        and recorded(_sound_goals(log), GOAL_COLUMNS)
        and recorded(_words_heard_through_model_6(log), REACHED_COLUMNS)
    )


def _understood(log: pd.DataFrame, names: set[str], distractors: set[str]) -> dict[str, float]:
    recognised = log[WORD_RECOGNISED].value_counts()
    understood = log.loc[log[WORD_RECOGNISED].isin(names), ITERATION]
    chosen = _chosen(log)
    toy_goals = chosen[chosen[MODEL].isin([m - 1 for m in VOICE_TOY_MODELS])]
    return {
        "recognised_names": float(sum(int(recognised.get(w, 0)) for w in names)),
        "recognised_distractors": float(sum(int(recognised.get(w, 0)) for w in distractors)),
        "name_recognised_after_toy_goal": (
            float(toy_goals[WORD_RECOGNISED].isin(names).mean()) if len(toy_goals) else math.nan
        ),
        "first_name_recognised": float(understood.min()) if len(understood) else math.nan,
    }


def _per_1000_arm(log: pd.DataFrame) -> tuple[pd.DataFrame, float]:
    arm = log[log[MOTOR_SPACE] == "arm"]
    return arm, 1000.0 / max(1, len(arm))


def _toys_moved(log: pd.DataFrame, names: set[str], distractors: set[str]) -> dict[str, float]:
    arm, per_1000 = _per_1000_arm(log)
    moved = arm[list(TOY_MOVED_BY)]
    return {
        "toy_held": float((moved == "hand").any(axis=1).sum() * per_1000),
        "toy_pushed": float((moved == "push").any(axis=1).sum() * per_1000),
    }


def _stick(log: pd.DataFrame, names: set[str], distractors: set[str]) -> dict[str, float]:
    arm, per_1000 = _per_1000_arm(log)
    return {
        "stick_held": float(arm[STICK_GRASPED].astype(bool).sum() * per_1000),
        "stick_pushed": float((arm[STICK_MOVED_BY] == "push").sum() * per_1000),
    }


@dataclass(frozen=True)
class _Numbers:
    """Some of the numbers, the columns they are read from, and whether a log recorded them
    (by default: every row holds every one of those columns)."""

    compute: Callable[[pd.DataFrame, set[str], set[str]], dict[str, float]]
    columns: tuple[str, ...]
    usable: Callable[[pd.DataFrame], bool] | None = None

    def recorded_in(self, log: pd.DataFrame) -> bool:
        return self.usable(log) if self.usable else recorded(log, self.columns)


_NUMBERS = (
    _Numbers(_shares, (MODEL,)),
    _Numbers(_heard, (MOTOR_SPACE, CAREGIVER_SAID)),
    _Numbers(_imitation, (MODEL, CAREGIVER_SAID, *GOAL_COLUMNS, *REACHED_COLUMNS), _goals_recorded),
    _Numbers(_understood, (ITERATION, MODEL, WORD_RECOGNISED)),
    _Numbers(_toys_moved, (MOTOR_SPACE, *TOY_MOVED_BY)),
    _Numbers(_stick, (MOTOR_SPACE, STICK_GRASPED, STICK_MOVED_BY)),
)
# The iterations log's columns `trial_mechanisms` reads (a reader may read only these:
# experiments/analysis/logs.read_log's `columns`).
LOG_COLUMNS = tuple(dict.fromkeys(c for part in _NUMBERS for c in part.columns))


def trial_mechanisms(log: pd.DataFrame, names: set[str], words: set[str]) -> dict[str, float]:
    """The module docstring's numbers for one trial; `names` its toy names, `words` all six.
    A number whose columns the log did not record in every row (a trial written before one
    existed) is NaN; the others are computed as usual."""
    distractors = words - names
    out: dict[str, float] = {}
    for part in _NUMBERS:
        if part.recorded_in(log):
            out |= part.compute(log, names, distractors)
    return {label: out.get(label, math.nan) for label in LABELS}


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
