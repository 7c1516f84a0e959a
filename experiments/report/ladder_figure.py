"""The contact ladder's waterfall: one panel per headline measure. The first bar is the first
rung's mean over its trials; each step (its rule given the rules before it, in this order)
floats from where the steps before it ended, its height the step's mean paired difference, its
whisker the step's 95% interval; the last bar is the last rung's own mean (where it and the
steps' end differ, the rungs' seeds or missing values differ). A rung beside the ladder floats,
hatched, from the last rung. Shares in percent."""

from __future__ import annotations

import math
import textwrap

import numpy as np
import pandas as pd
from matplotlib.figure import Figure

from experiments.report.ladder import BESIDE, OWN, STEP, Headline

COLUMNS = 4
TITLE_WIDTH = 50  # characters a panel's title line holds beside its neighbours' at this size
UP, DOWN, LEVEL = "tab:green", "tab:red", "0.6"


def _scale(h: Headline) -> float:
    return 100.0 if h.measure.kind == "share" else 1.0


def _panel(ax, h: Headline, steps: pd.DataFrame, levels: pd.DataFrame, order: list[str]) -> None:
    scale = _scale(h)
    mine = [dict(r) for r in steps[steps["key"] == h.key].to_dict("records")]
    own = levels[(levels["key"] == h.key) & (levels["tested"] == OWN)]
    level = {str(r): float(m) for r, m in zip(own["rung"], own["mean"], strict=True)}
    start = level.get(order[0], math.nan) * scale
    names = [f"{order[0]} (mean)"]
    ax.bar(0, start, color=LEVEL, width=0.7)
    running = start
    for i, step in enumerate((s for s in mine if s["kind"] == STEP), start=1):
        height = float(step["mean"]) * scale
        ax.bar(i, height, bottom=running, color=UP if height >= 0 else DOWN, width=0.7)
        if math.isfinite(step["low"]):
            low, high = float(step["low"]) * scale, float(step["high"]) * scale
            err = np.abs([[height - low], [high - height]])
            ax.errorbar(i, running + height, yerr=err, color="k", capsize=2, lw=0.8)
        running += height if math.isfinite(height) else 0.0
        names.append(str(step["to"]))
    last = len(names)
    ax.bar(last, level.get(order[-1], math.nan) * scale, color=LEVEL, width=0.7)
    names.append(f"{order[-1]} (own mean)")
    for j, step in enumerate((s for s in mine if s["kind"] == BESIDE), start=last + 1):
        base = level.get(order[-1], math.nan) * scale
        ax.bar(j, float(step["mean"]) * scale, bottom=base, color="w", edgecolor="k", hatch="//")
        names.append(f"{step['to']} (beside)")
    ax.axhline(0, color="k", lw=0.5)
    ax.set_xticks(range(len(names)), names, rotation=60, ha="right", fontsize=6)
    ax.set_title(textwrap.fill(h.label, TITLE_WIDTH), fontsize=7)
    ax.tick_params(axis="y", labelsize=6)


def waterfall(
    measures: list[Headline], steps: pd.DataFrame, levels: pd.DataFrame, order: list[str]
) -> Figure:
    """The figure (module docstring) of `ladder.step_tests`' and `ladder.levels`' tables."""
    rows = math.ceil(len(measures) / COLUMNS)
    fig = Figure(figsize=(3.2 * COLUMNS, 3.1 * rows), layout="constrained")
    axes = fig.subplots(rows, COLUMNS, squeeze=False).ravel()
    for ax, h in zip(axes, measures, strict=False):
        _panel(ax, h, steps, levels, order)
    for ax in axes[len(measures) :]:
        ax.set_visible(False)
    fig.suptitle(
        "Contact ladder: each rung's step given the rules before it, paired by seed (green up, "
        "red down, whisker 95% interval); grey: the first and last rungs' means; shares in %",
        fontsize=9,
    )
    return fig
