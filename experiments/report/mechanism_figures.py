"""The comparison's figures of why two sides differ, beside the paper's figures:
strategies with "tool" meaning the stick was held, what moved the goal toy in ring 1 after the
agent's movement and after a random one, the gap between the error the agent expected and the
error it got there, and the voice's social loop trial by trial."""

from __future__ import annotations

import numpy as np
import pandas as pd
from matplotlib.figure import Figure
from matplotlib.patches import Patch

from experiments.analysis.geometry import Geometry
from experiments.analysis.results import BatchResults
from experiments.analysis.strategies import MOVERS, held_strategy
from experiments.report.figures import (
    DPI,
    FigureFile,
    group_colour,
    png_bytes,
    strategy_by_distance,
)
from experiments.report.mechanisms import ring_outcomes

MOVER_COLOURS = {
    "hand": "tab:blue",
    "stick": "tab:orange",
    "caregiver": "tab:green",
    "push": "tab:red",
    "none": "lightgrey",
}
# Per-trial numbers of the voice's social loop (experiments/analysis/mechanisms.py, eval.json).
VOICE_LOOP = (
    ("heard_per_name", "times each name heard"),
    ("recognised_names", "vocal movements\nunderstood as a name"),
    ("name_recognised_after_toy_goal", "vocal toy goals that\nmade her bring a toy"),
    ("share_below_threshold", "words imitated\nwithin the threshold"),
)


def ring_outcome_figure(results: BatchResults, ring: int = 1) -> Figure | None:
    """Stacked shares of what moved the goal toy, agent vs random, per group; each segment
    labelled with the mean error it left."""
    table = ring_outcomes(results.competence, ring)
    if table.empty:
        return None
    fig = Figure(figsize=(8, 3.6), dpi=DPI, layout="constrained")
    ax = fig.add_subplot()
    bars = [(g, a) for g in results.groups for a in ("agent", "random")]
    for i, (group, actor) in enumerate(bars):
        rows = table[(table["group"] == group) & (table["actor"] == actor)].set_index("mover")
        left = 0.0
        for mover in MOVERS:
            share = float(rows["share"].get(mover, 0.0))
            if share <= 0:
                continue
            ax.barh(i, share, left=left, color=MOVER_COLOURS[mover])
            if share > 0.06:
                ax.text(
                    left + share / 2,
                    i,
                    f"{float(rows['mean_error'].get(mover, np.nan)):.2f}",
                    ha="center",
                    va="center",
                    fontsize=8,
                )
            left += share
    ax.set_yticks(range(len(bars)), [f"{g}\n{a}" for g, a in bars], fontsize=8)
    ax.invert_yaxis()
    ax.set_xlim(0, 1)
    ax.set_xlabel(f"share of ring {ring}'s tests (numbers: mean error those tests left)")
    handles = [Patch(color=c, label=m) for m, c in MOVER_COLOURS.items()]
    ax.legend(handles=handles, title="goal toy moved by", fontsize=8, loc="lower right")
    return fig


def expectation_figure(results: BatchResults, ring: int = 1) -> Figure:
    """Histogram per group of (error left - error expected from memory), ring `ring`'s arm
    tests."""
    fig = Figure(figsize=(6, 3.2), dpi=DPI, layout="constrained")
    ax = fig.add_subplot()
    bins = list(np.linspace(-0.6, 0.9, 46))
    for group in results.groups:
        tests = results.competence[results.competence["group"] == group]
        arm = tests[(tests["ring"] == ring) & (tests["strategy"] != "vocal") & ~tests["untrained"]]
        gap = (arm["error"] - arm["arm_nn_distance"]).to_numpy(dtype=float)
        if len(gap) == 0:  # no trained arm test in the ring: nothing to draw for this side
            continue
        colour = group_colour(results.groups, group)
        ax.hist(gap, bins=bins, histtype="step", color=colour, density=True, label=group)
        ax.axvline(np.mean(gap), color=colour, linestyle="--")
    ax.axvline(0, color="black", linewidth=0.8)
    ax.set_xlabel(f"error left − error expected from memory (ring {ring} arm tests)")
    ax.set_ylabel("density")
    if ax.get_legend_handles_labels()[0]:
        ax.legend(fontsize=8)
    return fig


def voice_loop_figure(results: BatchResults) -> Figure | None:
    """One panel per number of VOICE_LOOP: each trial a dot, per group, mean as a bar."""
    present = [(k, label) for k, label in VOICE_LOOP if k in results.trials.columns]
    if not present or results.trials[[k for k, _ in present]].isna().all(axis=None):
        return None
    fig = Figure(figsize=(3 * len(present), 3.2), dpi=DPI, layout="constrained")
    rng = np.random.default_rng(0)  # jitter only
    for i, (key, label) in enumerate(present):
        ax = fig.add_subplot(1, len(present), i + 1)
        for j, group in enumerate(results.groups):
            values = results.trials.loc[results.trials["group"] == group, key].to_numpy(float)
            colour = group_colour(results.groups, group)
            ax.scatter(j + rng.uniform(-0.15, 0.15, len(values)), values, s=8, color=colour)
            if np.isfinite(values).any():  # a side whose logs predate the numbers: no mean
                ax.hlines(np.nanmean(values), j - 0.3, j + 0.3, color="black")
        ax.set_xticks(range(len(results.groups)), results.groups, fontsize=8)
        ax.set_title(label, fontsize=9)
    return fig


def mechanism_figures(results: BatchResults, geometry: Geometry) -> list[FigureFile]:
    """The figures above that the results can draw."""
    out = []
    held = results.competence.assign(strategy=held_strategy(results.competence))
    if held["strategy"].notna().all():
        fig = strategy_by_distance(held, results.groups, geometry.hand_limit, geometry.stick_limit)
        out.append(
            (
                "strategies-stick-held.png",
                "Strategy preference by toy distance, tool = the stick was held",
                "As Fig. 4, but an arm test counts as tool use only when the hand held the "
                "stick; a stick only pushed counts as the hand. Like with like across backends.",
                fig,
            )
        )
    figures: list[tuple[str, str, str, Figure | None]] = [
        (
            "ring1-outcomes.png",
            "Ring 1: what moved the goal toy",
            "For the agent's chosen movement and for a random command in the very same scene "
            "(the project's measure plays both): the share of ring 1's tests in which the "
            "hand (held), the stick, the caregiver or a push moved the goal toy, or nothing "
            "did; the number in each segment is the mean error those tests left.",
            ring_outcome_figure(results),
        ),
        (
            "ring1-expected-error.png",
            "Ring 1: error expected from memory vs error left",
            "Arm tests within the hand's reach: the agent chose the movement whose remembered "
            "outcome lay nearest the goal; the histogram shows how much farther the movement, "
            "redone in the test's scene, left the toy. Dashed: means.",
            expectation_figure(results),
        ),
        (
            "voice-loop.png",
            "The voice's social loop, trial by trial",
            "From the logs: how often the caregiver said each toy name, how many vocal "
            "movements she understood as a name, the share of vocal goals on toys (models "
            "7-9) that made her bring one, and the share of words imitated within the "
            "threshold (eval.json). Dots: trials; bars: means.",
            voice_loop_figure(results),
        ),
    ]
    out += [(n, t, c, f) for n, t, c, f in figures if f is not None]
    return [FigureFile(name, title, caption, png_bytes(fig)) for name, title, caption, fig in out]


def replay_figure(table: pd.DataFrame) -> Figure:
    """Of `playroom replay`'s table: per backend, the mean error the
    remembered movement leaves in each scene, from where it was learned to the test's own,
    against the random command on the test's scene; and the error the goal toy's shift adds
    (test minus stick_at_start), by how far the toy lies from where it was remembered."""
    fig = Figure(figsize=(11, 3.6), dpi=DPI, layout="constrained")
    bars, shift = fig.add_subplot(1, 2, 1), fig.add_subplot(1, 2, 2)
    scenes = ("alone", "remembered", "stick_at_start", "test")
    groups = list(dict.fromkeys(table["grasp"]))
    width = 0.8 / len(groups)
    edges = [0.0, 0.02, 0.05, 0.1, 0.2, 0.4, 2.0]
    for j, group in enumerate(groups):
        rows = table[table["grasp"] == group]
        colour = group_colour(groups, group)
        x = np.arange(len(scenes)) + (j - (len(groups) - 1) / 2) * width
        bars.bar(x, [rows[f"error_{s}"].mean() for s in scenes], width, color=colour, label=group)
        bars.axhline(rows["random_error"].mean(), color=colour, linestyle="--")
        added = rows["error_test"] - rows["error_stick_at_start"]
        bins = pd.cut(rows["toy_shift"], edges)
        means = added.groupby(bins, observed=False).mean()
        shift.plot(np.arange(len(means)), means.to_numpy(), marker="o", color=colour, label=group)
    bars.set_xticks(range(len(scenes)), ["alone", "remembered", "stick at\nstart", "test"])
    bars.set_ylabel("mean error left (dashed: random command)")
    bars.legend(fontsize=8)
    labels = [f"{a:g}-{b:g}" for a, b in zip(edges[:-1], edges[1:], strict=True)]
    shift.set_xticks(range(len(labels)), labels, fontsize=8)
    shift.set_xlabel("goal toy's distance from where the movement met it (m)")
    shift.set_ylabel("error added by the toy's shift")
    shift.axhline(0, color="black", linewidth=0.8)
    shift.legend(fontsize=8)
    return fig
