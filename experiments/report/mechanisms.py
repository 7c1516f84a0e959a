"""Why two sides differ, as the logs and the tests show it (issue 32): rows of a comparison's
table of differences.

- From the logs (experiments/analysis/mechanisms.py): where exploration went, what the agent
  heard, what the caregiver understood, how arm movements moved things; per-trial values, mean
  with its interval over trials, Welch's t test.
- From the tests of ring 1 (the hand's reach): what the chosen movement did to the goal toy
  against what a random command did to it in the very same scene (the project's measure plays
  both on one scene; experiments/measure/evaluation.py), and the error each outcome left: a
  competence at or below random level is read off these rows.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from experiments.analysis.mechanisms import LABELS
from experiments.analysis.results import BatchResults
from experiments.analysis.stats import chi_square, mean_ci, welch
from experiments.analysis.strategies import MOVERS
from experiments.report.pages import num, p_value, pct

# Numbers shown as shares rather than counts.
SHARES = {k for k in LABELS if k.startswith("model_share_")} | {"name_recognised_after_toy_goal"}


def _text(values: np.ndarray, share: bool) -> str:
    mean, low, high = mean_ci(values)
    shown = (lambda x: pct(x, 1)) if share else (lambda x: num(x, 1))
    if not np.isfinite(mean):
        return "n/a"
    interval = "" if not np.isfinite(low) else f" [{shown(low)}, {shown(high)}]"
    return f"{shown(mean)}{interval} (n={np.isfinite(values).sum()})"


def log_rows(a: BatchResults, b: BatchResults) -> list[list[str]]:
    """One row per mechanism number both sides' logs hold."""
    rows = []
    for key, label in LABELS.items():
        if key not in a.trials.columns or key not in b.trials.columns:
            continue
        values = [s.trials[key].to_numpy(dtype=float) for s in (a, b)]
        if any(not np.isfinite(v).any() for v in values):
            continue
        rows.append(
            [
                f"Logs: {label}",
                *[_text(v, key in SHARES) for v in values],
                "Welch t (per-trial values)",
                p_value(welch(*values)[1]),
            ]
        )
    return rows


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


def ring_rows(a: BatchResults, b: BatchResults, ring: int = 1) -> list[list[str]]:
    """Ring `ring`: per actor, the goal toy's movers (shares, χ² of sides x movers) and, per
    mover, the mean error it left."""
    table = ring_outcomes(pd.concat([a.competence, b.competence]), ring)
    if table.empty:
        return []
    rows = []
    groups = [a.groups[0], b.groups[0]]
    for actor in ("agent", "random"):
        part = table[table["actor"] == actor]
        texts = []
        for g in groups:
            side = part[part["group"] == g]
            texts.append(
                ", ".join(
                    f"{r['mover']} {pct(r['share'])} (error {num(r['mean_error'])})"
                    for _, r in side.iterrows()
                    if r["count"] > 0
                )
            )
        counts = np.array([part[part["group"] == g]["count"].to_numpy() for g in groups])
        who = "the agent's chosen movement" if actor == "agent" else "a random command"
        rows.append(
            [
                f"Ring {ring} tests: what moved the goal toy after {who} (mean error left)",
                *texts,
                "χ² (pooled tests, sides × movers)",
                p_value(chi_square(counts)[1]),
            ]
        )
    return rows


def expectation_rows(a: BatchResults, b: BatchResults, ring: int = 1) -> list[list[str]]:
    """Ring `ring`'s arm tests: the error the agent expected (its memory's nearest outcome's
    distance to the goal, what it chose the movement by) against the error the movement left
    when redone in the test's scene. A gap says the same command does not repeat its outcome
    there: the scene differs from the remembered one in what the model's context does not hold,
    or the outcome is sensitive to it."""
    rows: list[list[str]] = []
    gaps: list[np.ndarray] = []
    texts: list[str] = []
    for side in (a, b):
        tests = side.competence
        arm = tests[(tests["ring"] == ring) & (tests["strategy"] != "vocal") & ~tests["untrained"]]
        expected = arm["arm_nn_distance"].to_numpy(dtype=float)
        realised = arm["error"].to_numpy(dtype=float)
        gap = realised - expected
        gaps.append(gap)
        if len(arm) == 0:  # no trained arm test in the ring: no row (below)
            continue
        texts.append(
            f"expected {num(np.mean(expected))}, left {num(np.mean(realised))}, "
            f"gap {num(np.mean(gap))} (n={len(arm)} tests)"
        )
    if any(len(g) == 0 for g in gaps):
        return rows
    rows.append(
        [
            f"Ring {ring} arm tests: error expected from memory vs left by the movement",
            *texts,
            "Welch t on the gaps (pooled tests)",
            p_value(welch(*gaps)[1]),
        ]
    )
    return rows


def comparison_rows(a: BatchResults, b: BatchResults) -> list[list[str]]:
    """The rows of all three kinds."""
    return [*ring_rows(a, b), *expectation_rows(a, b), *log_rows(a, b)]
