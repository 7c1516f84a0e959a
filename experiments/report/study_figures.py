"""Fig. 4 as the study computed it (experiments/analysis/study_maps.py), beside the paper's
numbers: one panel per group of trials that holds the study's tests."""

from __future__ import annotations

from matplotlib.figure import Figure

from experiments.analysis.results import BatchResults
from experiments.analysis.stats import STRATEGIES
from experiments.analysis.study_maps import strategy_curve
from experiments.analysis.study_summary import HAND_LIMIT, STICK_LIMIT
from experiments.report.figures import STRATEGY_COLOURS, FigureFile, png_bytes
from experiments.report.paper import PaperNumber

# The paper's regions on Fig. 4's axis, where its numbers are drawn.
PAPER_REGIONS = {
    "strategy_centre": (0.0, HAND_LIMIT),
    "strategy_between_limits": (HAND_LIMIT, STICK_LIMIT),
}


def _draw_paper(axis, published: dict[str, PaperNumber]) -> None:
    """The paper's shares: a band (a range) or a line (a value) over each region, and points
    at distance 1."""
    for key, (start, end) in PAPER_REGIONS.items():
        for strategy, value in published[key].value.items():
            low, high = (value, value) if isinstance(value, float) else value
            colour = STRATEGY_COLOURS[strategy]
            if low == high:
                axis.hlines(100 * low, start, end, colors=colour, linestyles=":", linewidth=2)
            else:
                axis.fill_between([start, end], 100 * low, 100 * high, color=colour, alpha=0.12)
    for strategy, value in published["strategy_distance_1"].value.items():
        axis.plot(1.0, 100 * value, "*", color=STRATEGY_COLOURS[strategy], markersize=12)


def study_strategy_figure(results: BatchResults, published: dict[str, PaperNumber]) -> Figure:
    """Per group with study tests: the hand, tool and vocal shares of Fig. 4's curve, the
    paper's numbers over them."""
    tests = results.study_tests
    groups = [g for g in results.groups if (tests["group"] == g).any()]
    fig = Figure(figsize=(5.6 * len(groups), 4.4), layout="constrained")
    axes = fig.subplots(1, len(groups), squeeze=False, sharey=True)[0]
    for axis, group in zip(axes, groups, strict=True):
        curve = strategy_curve(tests[tests["group"] == group])
        for strategy in STRATEGIES:
            axis.plot(
                curve["x"],
                100 * curve[strategy],
                color=STRATEGY_COLOURS[strategy],
                linewidth=2,
                label=strategy,
            )
        _draw_paper(axis, published)
        for limit in (HAND_LIMIT, STICK_LIMIT):
            axis.axvline(limit, color="black", linestyle="--", linewidth=1)
        axis.set_title(group)
        axis.set_xlabel("toy distance to the arm's base (m; Fig. 4's axis: pixel bin / 49)")
        axis.set_xlim(0.0, 1.03)
        axis.set_ylim(0.0, 100.0)
    axes[0].set_ylabel("strategy use (%)")
    axes[0].legend(loc="upper left", fontsize=8)
    return fig


def study_figure_files(
    results: BatchResults, published: dict[str, PaperNumber]
) -> list[FigureFile]:
    """The study's Fig. 4 as a report figure; none when no trial holds the study's tests."""
    if results.study_tests.empty:
        return []
    return [
        FigureFile(
            "fig4-strategies-as-the-study-computed-it.png",
            "Strategy preference by toy distance, as the study computed it (paper Fig. 4)",
            "The study's curve: each pixel's shares of hand, tool and vocal tests pooled over "
            "trials, averaged over one-pixel radial bins, renormalised in the notebook's order "
            "(docs/protocol.md §10). Paper's numbers: bands (ranges) and dotted lines (values) "
            "over the regions it describes, stars at distance 1. Dashed: the limits 0.6, 0.85.",
            png_bytes(study_strategy_figure(results, published)),
        )
    ]
