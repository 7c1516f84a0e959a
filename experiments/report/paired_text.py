"""How the generated pages write a paired comparison over seeds (the contact ladder's,
the factorial's, the ablation table's): a difference with its 95% interval, the paired t's p
and the Wilcoxon signed-rank p beside it, each starred where it survives Holm's correction
over the page's family of tests."""

from __future__ import annotations

import math

from experiments.analysis.trial_tests import survives
from experiments.report.pages import p_value


def signed_text(kind: str, x: float) -> str:
    """A difference of a measure of `kind` with its sign: percentage points for shares."""
    if not math.isfinite(x):
        return "n/a"
    return (
        f"{100 * x:+.1f}"
        if kind == "share"
        else f"{x:+.3f}"
        if kind == "distance"
        else (f"{x:+.2f}" if kind == "ratio" else f"{x:+.1f}")
    )


def level_text(kind: str, x: float) -> str:
    """A level (a mean) of a measure of `kind`, as `signed_text` without the sign."""
    return signed_text(kind, x).lstrip("+")


def p_text(p: float, adjusted: float) -> str:
    """A p, with * where its Holm-adjusted value survives."""
    return p_value(p) + (" *" if survives(adjusted) else "")


def cell_text(kind: str, row: dict) -> str:
    """A difference as "+1.5 [-0.0, +3.0], p = 0.054; rank p = 0.061 (32)": the paired t's p,
    then the signed-rank test's, each * where it survives Holm over the page's family."""
    n = int(row["n"])
    if not math.isfinite(row["mean"]):
        return f"n/a ({n} pairs)"
    low, high = signed_text(kind, row["low"]), signed_text(kind, row["high"])
    text = f"{signed_text(kind, row['mean'])} [{low}, {high}]"
    if not math.isfinite(row["p"]):
        why = "fewer than 2 pairs" if n < 2 else "every pair equal"
        return f"{text}, untested: {why} ({n})"
    t = p_text(row["p"], row["p_holm"])
    rank = rank_text(row["p_rank"], row["p_rank_holm"])
    return f"{text}, {t}; {rank} ({n})"


def rank_text(p: float, adjusted: float) -> str:
    """A signed-rank p, as "rank p = 0.061" with * where it survives Holm."""
    return p_text(p, adjusted).replace("p ", "rank p ", 1)
