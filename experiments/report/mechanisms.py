"""What moved the goal toy in a ring's tests, for the comparison's figure
(experiments/report/mechanism_figures.py): what the chosen movement did to the goal toy against
what a random command did to it in the very same scene (the project's measure plays both on one
scene; experiments/measure/evaluation.py), and the error each outcome left: a competence at or
below random level is read off it. The comparison's rows of these numbers, and of the logs'
per-trial mechanism numbers, are measures of experiments/report/measures.py, tested over
trials there.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from experiments.analysis.strategies import MOVERS


def ring_outcomes(competence: pd.DataFrame, ring: int = 1) -> pd.DataFrame:
    """Per group, mover and who acted (agent, random): the share of ring `ring`'s tests in
    which that mover moved the goal toy, and the mean error those tests left. Columns group,
    actor, mover, share, count, mean_error. Empty for tests evaluated before it was recorded."""
    needed = {"goal_moved_by", "random_goal_moved_by"}
    tests = competence[competence["ring"] == ring]
    if not needed <= set(tests.columns) or tests[list(needed)].isna().any(axis=None):
        return pd.DataFrame(columns=["group", "actor", "mover", "share", "count", "mean_error"])
    rows = []
    for group, table in tests.groupby("group", sort=False):
        for actor, mover_column, error_column in (
            ("agent", "goal_moved_by", "error"),
            ("random", "random_goal_moved_by", "random_error"),
        ):
            for mover in MOVERS:
                chosen = table[table[mover_column] == mover]
                rows.append(
                    {
                        "group": group,
                        "actor": actor,
                        "mover": mover,
                        "share": len(chosen) / len(table) if len(table) else np.nan,
                        "count": len(chosen),
                        "mean_error": chosen[error_column].mean() if len(chosen) else np.nan,
                    }
                )
    return pd.DataFrame(rows)
