"""The positive control's figure (`playroom rl-control`, experiments/baseline/control_run.py),
from its table alone: one panel per goal, the success on the held-out goals against the
movements given, each seed of the learner a thin line and their mean a thick one, the other
actors of the table (references on the same goals) as their mean over seeds, and a goal's
target as a dotted line."""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import pandas as pd
from matplotlib.figure import Figure

from experiments.report.figures import png_bytes

# The learner's colour and line, then the references' in the order given.
COLOURS = ("tab:blue", "tab:orange", "tab:grey", "tab:green")
STYLES = ("-", "--", ":", "-.")


def control_figure(
    table: pd.DataFrame, actors: Sequence[str], targets: Mapping[str, float]
) -> Figure:
    """The curves of `table` (columns goal, seed, learner, steps, success): `actors[0]`, the
    learner, per seed and on average, the other actors on average; `targets[goal]` dash-dotted."""
    goals = list(dict.fromkeys(table["goal"]))
    learner = actors[0]
    fig = Figure(figsize=(4.6 * len(goals), 3.6), layout="constrained")
    axes = fig.subplots(1, len(goals), squeeze=False, sharey=True)[0]
    for ax, goal in zip(axes, goals, strict=True):
        rows = table[table["goal"] == goal]
        for i, actor in enumerate(actors):
            mine = rows[rows["learner"] == actor]
            colour, style = COLOURS[i % len(COLOURS)], STYLES[i % len(STYLES)]
            if actor == learner:
                for _, seed in mine.groupby("seed"):
                    ax.plot(seed["steps"], 100 * seed["success"], color=colour, lw=0.7, alpha=0.5)
            mean = mine.groupby("steps")["success"].mean()
            seeds = mine["seed"].nunique()
            label = f"{actor} (mean of {seeds} seed{'s' * (seeds != 1)})"
            lw = 2.0 if actor == learner else 1.2
            ax.plot(mean.index, 100 * mean.to_numpy(), color=colour, ls=style, lw=lw, label=label)
        if goal in targets:
            ax.axhline(100 * targets[goal], color="k", ls="-.", lw=0.7, label="target")
        ax.set_title(f"{goal} goal", fontsize=9)
        ax.set_xlabel("movements given")
        ax.set_ylim(-2, 102)
    axes[0].set_ylabel("held-out goals reached (%)")
    axes[0].legend(fontsize=7, loc="center right")
    return fig


def control_png(table: pd.DataFrame, actors: Sequence[str], targets: Mapping[str, float]) -> bytes:
    return png_bytes(control_figure(table, actors, targets))
