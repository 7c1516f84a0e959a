"""The race's figure (`playroom rl-race`, experiments/baseline/race_run.py), from its table
alone: a row of panels per grasp backend, one per ring (near, far, all), the success on the
held-out toy goals against the movements given, each learner's mean over seeds as a thick line
and each seed as a thin one."""

from __future__ import annotations

from collections.abc import Sequence

import pandas as pd
from matplotlib.figure import Figure

from experiments.report.figures import png_bytes

# Each learner's colour, in the order given (Model Babbling's first).
COLOURS = ("tab:green", "tab:orange", "tab:blue", "tab:grey")
RINGS = ("near", "far", "all")
# The y axis ends this far above the highest success drawn (a share of it), and never below
# FLOOR_PERCENT: success near 0 everywhere would otherwise be flat lines on a 0-100 axis.
HEADROOM = 1.15
FLOOR_PERCENT = 1.0


def race_figure(table: pd.DataFrame, learners: Sequence[str]) -> Figure:
    """The curves of `table` (columns learner, grasp, seed, steps, ring, success), a colour for
    each of `learners`."""
    colours = {learner: COLOURS[i % len(COLOURS)] for i, learner in enumerate(learners)}
    grasps = list(dict.fromkeys(table["grasp"]))
    fig = Figure(figsize=(4.2 * len(RINGS), 3.2 * len(grasps)), layout="constrained")
    axes = fig.subplots(len(grasps), len(RINGS), squeeze=False, sharey=True)
    top = min(100.0, max(FLOOR_PERCENT, HEADROOM * 100 * float(table["success"].max())))
    for row, grasp in zip(axes, grasps, strict=True):
        for ax, ring in zip(row, RINGS, strict=True):
            rows = table[(table["grasp"] == grasp) & (table["ring"] == ring)]
            for learner, mine in rows.groupby("learner", sort=False):
                colour = colours.get(str(learner), COLOURS[-1])
                for _, seed in mine.groupby("seed"):
                    ax.plot(seed["steps"], 100 * seed["success"], color=colour, lw=0.6, alpha=0.4)
                mean = mine.groupby("steps")["success"].mean()
                seeds = mine["seed"].nunique()
                label = f"{learner} (mean of {seeds} seed{'s' * (seeds != 1)})"
                ax.plot(mean.index, 100 * mean.to_numpy(), color=colour, lw=2.0, label=label)
            ax.set_title(f"{grasp} grasp, {ring} goals", fontsize=9)
            ax.set_xlabel("movements given")
            ax.set_ylim(-0.02 * top, top)
        row[0].set_ylabel("held-out toy goals reached (%)")
    axes[0][0].legend(fontsize=7, loc="upper left")
    return fig


def race_png(table: pd.DataFrame, learners: Sequence[str]) -> bytes:
    return png_bytes(race_figure(table, learners))
