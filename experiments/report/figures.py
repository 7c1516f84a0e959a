"""The figures of a batch report, one per result of the paper, drawn with matplotlib.

Every function takes the tables of `experiments.analysis.results.BatchResults` and returns a
`matplotlib.figure.Figure` holding one panel (or one line) per group of trials, so that the
same figure serves a single batch and a comparison of two. Figures are built without pyplot:
no global state, no display, the Agg canvas renders them to PNG. `report_figures` draws
them all, with the titles and captions the report shows.
"""

from __future__ import annotations

import io
from typing import NamedTuple

import numpy as np
import pandas as pd
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure
from matplotlib.patches import Circle
from matplotlib.ticker import MaxNLocator

from experiments.analysis.geometry import Geometry
from experiments.analysis.results import BatchResults
from experiments.analysis.stats import STRATEGIES, competence_summary, curve_bands

STRATEGY_COLOURS = {"hand": "tab:blue", "tool": "tab:orange", "vocal": "tab:green"}
# Groups take colours in order, the same in every figure of a report.
GROUP_COLOURS = ("tab:purple", "tab:red", "tab:cyan", "tab:olive", "tab:brown", "tab:pink")
# Below this many rows per grid cell (on average), the competence map uses coarser cells.
ROWS_PER_CELL = 8
DPI = 110


def group_colour(groups: list[str], group: str) -> str:
    return GROUP_COLOURS[groups.index(group) % len(GROUP_COLOURS)]


def png_bytes(fig: Figure) -> bytes:
    """The figure as PNG bytes (Agg canvas)."""
    FigureCanvasAgg(fig)
    buffer = io.BytesIO()
    fig.savefig(buffer, format="png", dpi=DPI)
    return buffer.getvalue()


def _panels(
    n: int, width: float = 5.2, height: float = 4.6, sharey: bool = False
) -> tuple[Figure, list]:
    fig = Figure(figsize=(width * n, height), layout="constrained")
    axes = fig.subplots(1, n, squeeze=False, sharey=sharey)[0]
    return fig, list(axes)


def competence_map_grid(
    rows: pd.DataFrame, n_bins: int | None = None
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(edges, competence[ix, iy], counts[ix, iy]) of rows with x, y, error, random_error on a
    square grid over [-1, 1]^2. A cell's competence is 1 - sum(error) / sum(random error),
    the same ratio of means as a trial's normalised competence, so that cells where the
    random agent happens to come close to the goal do not blow up; empty cells are NaN."""
    if n_bins is None:
        n_bins = int(np.clip(np.sqrt(len(rows) / ROWS_PER_CELL), 6, 25))
    edges = np.linspace(-1.0, 1.0, n_bins + 1)
    counts, _, _ = np.histogram2d(rows["x"], rows["y"], bins=[edges, edges])
    err, _, _ = np.histogram2d(rows["x"], rows["y"], bins=[edges, edges], weights=rows["error"])
    rnd, _, _ = np.histogram2d(
        rows["x"], rows["y"], bins=[edges, edges], weights=rows["random_error"]
    )
    with np.errstate(invalid="ignore", divide="ignore"):
        competence = np.where((counts > 0) & (rnd > 0), 1.0 - err / rnd, np.nan)
    return edges, competence, counts


def competence_map_figure(
    competence: pd.DataFrame, groups: list[str], hand_limit: float, stick_limit: float
) -> Figure:
    """Fig. 3: normalised competence to bring a toy to the centre, by the toy's position."""
    fig, axes = _panels(len(groups))
    mesh = None
    for ax, group in zip(axes, groups, strict=True):
        rows = competence[competence["group"] == group]
        edges, grid, counts = competence_map_grid(rows)
        # Percent, clipped at -100%: worse than twice the random agent's error reads the same.
        mesh = ax.pcolormesh(
            edges, edges, 100 * grid.T, cmap="RdYlGn", vmin=-100, vmax=100, shading="flat"
        )
        for radius, label in ((hand_limit, "hand limit"), (stick_limit, "stick limit")):
            ax.add_patch(Circle((0, 0), radius, fill=False, ls="--", lw=1.2, color="k"))
            ax.annotate(label, (radius * np.cos(np.pi / 4), radius * np.sin(np.pi / 4)), fontsize=8)
        ax.add_patch(Circle((0, 0), 1.0, fill=False, ls=":", lw=1.0, color="k"))
        ax.plot(0, 0, marker="+", color="k", ms=10)
        mean = 100 * (1 - rows["error"].mean() / rows["random_error"].mean())
        ax.set_title(f"{group}: {mean:+.0f}% overall ({len(rows)} tests)")
        ax.set_xlim(-1, 1)
        ax.set_ylim(-1, 1)
        ax.set_aspect("equal")
        ax.set_xticks([-1, -0.5, 0, 0.5, 1])
        ax.set_yticks([-1, -0.5, 0, 0.5, 1])
        ax.set_xlabel("toy x (m from the arm's base)")
        ax.set_ylabel("toy y (m from the arm's base)")
    assert mesh is not None, "no group to draw"
    bar = fig.colorbar(mesh, ax=axes, shrink=0.85, extend="min")
    bar.set_label("normalised competence (%)\n0 = random agent, 100 = perfect")
    fig.suptitle("Competence to bring a toy to the centre\nby toy position (paper Fig. 3)")
    return fig


def strategy_shares_by_distance(
    competence: pd.DataFrame, bin_width: float
) -> tuple[np.ndarray, pd.DataFrame, np.ndarray]:
    """(bin centres, shares[bin x strategy], counts per bin) of strategies by toy distance."""
    edges = np.arange(0.0, 1.0 + bin_width / 2, bin_width)
    which = np.clip(np.digitize(competence["distance"], edges) - 1, 0, len(edges) - 2)
    table = pd.crosstab(which, competence["strategy"]).reindex(
        index=range(len(edges) - 1), columns=list(STRATEGIES), fill_value=0
    )
    counts = table.sum(axis=1).to_numpy()
    with np.errstate(invalid="ignore", divide="ignore"):
        shares = table.div(counts, axis=0)
    return (edges[:-1] + edges[1:]) / 2, shares, counts


def strategy_by_distance(
    competence: pd.DataFrame, groups: list[str], hand_limit: float, stick_limit: float
) -> Figure:
    """Fig. 4: how often each strategy is chosen, by the toy's distance to the arm's base."""
    fig, axes = _panels(len(groups))
    for ax, group in zip(axes, groups, strict=True):
        rows = competence[competence["group"] == group]
        # 20 bins as in the paper's figure when there is enough data, else 10.
        width = 0.05 if len(rows) >= 20 * 30 else 0.1
        centres, shares, counts = strategy_shares_by_distance(rows, width)
        for s in STRATEGIES:
            ax.plot(centres, 100 * shares[s], marker="o", ms=4, color=STRATEGY_COLOURS[s], label=s)
        for x, label in ((hand_limit, "hand limit"), (stick_limit, "stick limit")):
            ax.axvline(x, color="k", lw=1.5)
            ax.text(x + 0.01, 97, label, fontsize=8, va="top")
        ax.set_xlim(0, 1)
        ax.set_ylim(0, 100)
        ax.set_xlabel("toy distance to the arm's base (m)")
        ax.set_ylabel("share of tests (%)")
        ax.set_title(f"{group} ({len(rows)} tests, at least {int(counts.min())} per bin)")
        ax.grid(alpha=0.3)
    # One legend for all panels, under them: inside a panel it would hide some curve.
    handles, labels = axes[0].get_legend_handles_labels()
    fig.legend(handles, labels, loc="outside lower center", ncols=3, title="strategy")
    fig.suptitle("Strategy chosen to retrieve a toy\nby its distance (paper Fig. 4)")
    return fig


def vocal_errors(vocal: pd.DataFrame, groups: list[str], threshold: float) -> Figure:
    """Fig. 5: best imitation error of each word, toy names against distractors."""
    # One count scale for all panels, so that two batches compare at a glance.
    fig, axes = _panels(len(groups), sharey=True)
    finite = vocal["best_distance"][np.isfinite(vocal["best_distance"])]
    top = max(1.2, float(finite.max()) if len(finite) else 1.2)
    edges = np.arange(0.0, top + 0.05, 0.05)
    for ax, group in zip(axes, groups, strict=True):
        rows = vocal[vocal["group"] == group]
        for is_name, label, colour in (
            (True, "toy names", "tab:blue"),
            (False, "distractors", "tab:orange"),
        ):
            values = rows.loc[rows["is_name"] == is_name, "best_distance"]
            values = values[np.isfinite(values)]
            ax.hist(
                values,
                bins=edges,
                histtype="stepfilled",
                alpha=0.45,
                color=colour,
                edgecolor=colour,
                label=f"{label} (n={len(values)}, median {values.median():.2f})",
            )
        ax.axvline(
            threshold, color="k", ls="--", lw=1.5, label=f"recognition threshold {threshold}"
        )
        below = (rows["best_distance"] < threshold).mean()
        ax.set_title(f"{group}: {100 * below:.0f}% of words below {threshold}")
        ax.set_xlabel(
            "best distance between the word and the agent's sounds\n(formant features, log2 Hz)"
        )
        ax.set_ylabel("number of words")
        ax.yaxis.set_major_locator(MaxNLocator(integer=True))
        ax.set_xlim(0, top)
        ax.legend(fontsize=8)
    fig.suptitle("Accuracy of imitations of the caregiver's words\n(paper Fig. 5)")
    return fig


def development(bands: pd.DataFrame, groups: list[str], bootstrap: int, threshold: float) -> Figure:
    """Developmental curves: tool use, recognised words and best word distance over time.
    `bands`: group, metric, iteration, mean, low, high
    (`experiments.analysis.stats.curve_bands`)."""
    fig, axes = _panels(3, width=5.0, height=4.2)
    # (axis, [(metric, line style)], y label, scale, largest possible value): intervals are
    # clipped to what a share or a distance can be, the t interval of few trials is not.
    panels = (
        (axes[0], [("tool_use", "-")], "toy moved with the stick (% of arm movements)", 100, 1),
        (axes[1], [("word_recognised", "-")], "word recognised (% of vocal movements)", 100, 1),
        (
            axes[2],
            [("best_distance_names", "-"), ("best_distance_distractors", "--")],
            "best distance to the caregiver's words (log2 Hz)",
            1,
            np.inf,
        ),
    )
    _band_panels(panels, bands, groups, bootstrap)
    for ax in axes[:2]:
        ax.set_ylim(bottom=0)  # shares: an axis fitted to the data would exaggerate changes
    axes[2].axhline(threshold, color="k", lw=1, ls=":", label=f"threshold {threshold}")
    axes[0].set_title("Tool use")
    axes[1].set_title("Words the caregiver recognised")
    axes[2].set_title("Best imitation so far")
    for ax in axes:
        handles, labels = ax.get_legend_handles_labels()
        if handles:
            ax.legend(fontsize=8)
    axes[0].text(
        bootstrap / 2,
        0.97,
        "random\nbootstrap",
        transform=axes[0].get_xaxis_transform(),
        ha="center",
        va="top",
        fontsize=8,
        color="0.4",
    )
    fig.suptitle("Development over iterations (mean over trials, 95% interval shaded)")
    return fig


def _band_panels(panels: tuple, bands: pd.DataFrame, groups: list[str], bootstrap: int) -> None:
    """Draw curves with their intervals: panels of (axis, [(metric, line style)], y label,
    scale, largest possible value), the random bootstrap shaded grey."""
    for ax, metrics, ylabel, scale, top in panels:
        ax.axvspan(0, bootstrap, color="0.9", zorder=0)
        for group in groups:
            colour = group_colour(groups, group)
            for metric, style in metrics:
                band = bands[(bands["group"] == group) & (bands["metric"] == metric)]
                if band.empty:
                    continue
                label = group
                if metric.startswith("best_distance"):
                    label += ", " + metric.removeprefix("best_distance_")
                ax.plot(
                    band["iteration"], scale * band["mean"], ls=style, color=colour, label=label
                )
                ax.fill_between(
                    band["iteration"],
                    scale * band["low"].clip(0, top),
                    scale * band["high"].clip(0, top),
                    color=colour,
                    alpha=0.2,
                    lw=0,
                )
        ax.set_xlabel("iteration (movements since the start)")
        ax.set_ylabel(ylabel)
        ax.set_xlim(left=0)
        ax.grid(alpha=0.3)


def stick_in_play(bands: pd.DataFrame, groups: list[str], bootstrap: int) -> Figure:
    """The stick as a tool over time: within reach, grasped, catching toys."""
    fig, axes = _panels(3, width=5.0, height=4.2)
    panels = (
        (axes[0], [("stick_in_reach", "-")], "stick within reach (% of iterations)", 100, 1),
        (axes[1], [("stick_grasp", "-")], "stick grasps per 1000 arm movements", 1000, 1),
        (axes[2], [("tool_use", "-")], "toys caught per 1000 arm movements", 1000, 1),
    )
    _band_panels(panels, bands, groups, bootstrap)
    # The whole 0-100% range: the share stays near 100%, and an axis fitted to the data
    # (97.5-100%) made dips of a point look like collapses.
    axes[0].set_ylim(0, 100)
    for ax in axes[1:]:
        ax.set_ylim(bottom=0)  # rates: zero is the honest floor
    for ax, title in zip(axes, ("Stick within reach", "Stick grasped", "Toy caught"), strict=True):
        ax.set_title(title)
        if ax.get_legend_handles_labels()[0]:
            ax.legend(fontsize=8)
    fig.suptitle("The stick in play (mean over trials, 95% interval shaded)")
    return fig


def competence_by_ring(
    trials: pd.DataFrame, summary: pd.DataFrame, groups: list[str], paper_mean: float
) -> Figure:
    """Per-trial normalised competence, overall and per ring (dots), with the means and 95%
    intervals of `summary` (group, scope, mean, low, high: `stats.competence_summary`)."""
    scopes = list(dict.fromkeys(summary["scope"]))
    fig = Figure(figsize=(9.0, 4.6), layout="constrained")
    ax = fig.subplots()
    rng = np.random.default_rng(0)  # jitter only, fixed so that figures are reproducible
    width = 0.7 / len(groups)
    for g, group in enumerate(groups):
        rows = trials[trials["group"] == group]
        colour = group_colour(groups, group)
        for i, scope in enumerate(scopes):
            x = i - 0.35 + width * (g + 0.5)
            values = 100 * rows[f"competence_{scope}"].to_numpy()
            jitter = rng.uniform(-width / 4, width / 4, len(values))
            ax.scatter(x + jitter, values, s=12, color=colour, alpha=0.5, lw=0)
            stat = summary[(summary["group"] == group) & (summary["scope"] == scope)].iloc[0]
            mean, low, high = 100 * stat["mean"], 100 * stat["low"], 100 * stat["high"]
            yerr = None if np.isnan(low) else [[mean - low], [high - mean]]
            label = f"{group} ({len(rows)} trials)" if i == 0 else None
            ax.errorbar(x, mean, yerr=yerr, fmt="D", color=colour, capsize=4, ms=6, label=label)
    ax.axhline(0, color="k", lw=1)
    ax.axhline(
        100 * paper_mean, color="0.3", ls="--", lw=1, label=f"paper: {paper_mean:.0%} on average"
    )
    names = {"all": "all rings"}
    ax.set_xticks(range(len(scopes)), [names.get(s, s.replace("ring", "ring ")) for s in scopes])
    ax.set_ylabel("normalised competence (%): 0 = random agent")
    ax.set_title("Competence per trial (dots), mean and 95% interval (diamonds)")
    ax.legend(fontsize=8, loc="upper left", bbox_to_anchor=(1.01, 1.0))
    ax.grid(alpha=0.3, axis="y")
    return fig


class FigureFile(NamedTuple):
    """A figure of the report as a file: name (e.g. fig3-competence-map.png), title and
    caption (plain text, shown beside it) and its PNG bytes."""

    name: str
    title: str
    caption: str
    png: bytes


def report_figures(
    results: BatchResults, geometry: Geometry, paper_mean: float
) -> list[FigureFile]:
    """Every figure of a report, one panel or line per group; `paper_mean`: the paper's mean
    normalised competence (a fraction), drawn as a reference line."""
    g = results.groups
    drawn = [
        (
            "fig3-competence-map.png",
            "Competence by toy position (paper Fig. 3)",
            "Normalised competence 1 − Σerror / Σrandom error of the tests whose toy lies in "
            "each cell, pooled over trials: 0% is the random agent on the same placements, 100% "
            "a perfect retrieval. Dashed circles: hand and stick reach limits.",
            competence_map_figure(results.competence, g, geometry.hand_limit, geometry.stick_limit),
        ),
        (
            "fig4-strategies.png",
            "Strategy preference by toy distance (paper Fig. 4)",
            "Share of tests in which the agent chose the hand (arm, stick still), the tool "
            "(arm, stick moved) or its voice (caregiver's help), by the toy's distance to the "
            "arm's base. Vertical bars: hand and stick reach limits.",
            strategy_by_distance(results.competence, g, geometry.hand_limit, geometry.stick_limit),
        ),
        (
            "fig5-vocal-errors.png",
            "Vocal imitation errors, toy names vs distractors (paper Fig. 5)",
            "Best (lowest) distance between each of the caregiver's words and any sound the "
            f"agent produced; below {geometry.threshold:g} the caregiver recognises the word.",
            vocal_errors(results.vocal, g, geometry.threshold),
        ),
        (
            "development.png",
            "Developmental curves",
            "Per window of iterations, mean over trials with a 95% interval: share of arm "
            "movements that moved a toy with the stick, share of vocal movements the caregiver "
            "recognised as a word, and mean best distance so far to the trial's toy names "
            "(solid) and distractors (dashed). Grey: the random bootstrap.",
            development(curve_bands(results.curves), g, geometry.bootstrap, geometry.threshold),
        ),
        (
            "stick.png",
            "The stick in play",
            "Per window of iterations, mean over trials with a 95% interval: share of "
            "iterations that began with the stick within the hand's reach, stick grasps and "
            "toys caught with the stick per 1000 arm movements.",
            stick_in_play(curve_bands(results.curves), g, geometry.bootstrap),
        ),
        (
            "competence-per-trial.png",
            "Competence per trial and ring",
            "Each dot is one trial's normalised competence; diamonds: mean with 95% t interval.",
            competence_by_ring(results.trials, competence_summary(results.trials), g, paper_mean),
        ),
    ]
    return [FigureFile(name, title, caption, png_bytes(fig)) for name, title, caption, fig in drawn]
