"""What the race may claim (race_run.py's table): at each budget, grasp backend and ring, each deep
RL learner's success beside Model Babbling's, paired by seed (the same trial's seed, world and
movements), with a two-sided Wilcoxon signed-rank test over the seeds' differences
(scipy.stats.wilcoxon). A difference is claimed only where the test rejects equality at
race_settings.py's ALPHA; otherwise the row says none is shown. Every sentence the page says of
the race is one of these rows."""

from __future__ import annotations

import numpy as np
import pandas as pd
from scipy import stats

from experiments.baseline.race_settings import ALPHA, MODEL_BABBLING

HIGHER, LOWER, NONE_SHOWN = "Model Babbling higher", "Model Babbling lower", "no difference shown"
COLUMNS = [
    "grasp",
    "ring",
    "steps",
    "learner",
    "seeds",
    "model_babbling",
    "learner_success",
    "mean_difference",
    "p_value",
    "claim",
]


def paired_p(differences: np.ndarray) -> float:
    """The two-sided Wilcoxon signed-rank p-value of paired differences; 1.0 where every one
    is zero (nothing to rank: no difference to claim)."""
    if not np.any(differences):
        return 1.0
    return float(stats.wilcoxon(differences, alternative="two-sided").pvalue)


def claims(table: pd.DataFrame, alpha: float = ALPHA) -> pd.DataFrame:
    """One row per (grasp, ring, steps, deep RL learner) with both learners on the same seeds
    (COLUMNS): the means over those seeds, Model Babbling's less the learner's, p and the
    claim."""
    keys = ["grasp", "ring", "steps", "seed"]
    ours = table[table["learner"] == MODEL_BABBLING].set_index(keys)["success"]
    rows = []
    for learner, theirs in table[table["learner"] != MODEL_BABBLING].groupby("learner"):
        paired = pd.concat([ours, theirs.set_index(keys)["success"]], axis=1, join="inner")
        paired.columns = ["mb", "rl"]
        for (grasp, ring, steps), one in paired.groupby(level=["grasp", "ring", "steps"]):
            differences = (one["mb"] - one["rl"]).to_numpy()
            p = paired_p(differences)
            mean = float(differences.mean())
            claim = NONE_SHOWN if p >= alpha else (HIGHER if mean > 0 else LOWER)
            rows.append([grasp, ring, steps, learner, len(one), one["mb"].mean(),
                         one["rl"].mean(), mean, p, claim])  # fmt: skip
    return pd.DataFrame(rows, columns=COLUMNS)
