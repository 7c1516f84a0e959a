"""Two batches side by side (`playroom compare DIR_A DIR_B --out DIR`): every figure with one
panel per side, the paper table with both, and tests of whether their differences are real.

A side is one group of trials: two batches of one group each (e.g. kinematic and physical
grasping run apart), or one batch of exactly two groups compared with itself.
"""

from __future__ import annotations

import math
import os
from pathlib import Path

import numpy as np
import pandas as pd
from scipy import stats

from experiments import provenance
from experiments.analysis.geometry import Geometry
from experiments.analysis.results import (
    COMPETENCE_SCOPES,
    BatchResults,
    ReportError,
    check_out_dir,
    collect,
)
from experiments.analysis.room_measures import RoomMeasures
from experiments.analysis.stats import (
    STRATEGIES,
    chi_square,
    competence_summary,
    cost_per_iteration,
    mann_whitney,
    regions,
    strategy_counts,
    strategy_table,
    welch,
)
from experiments.file_names import COMPARISON_FILE
from experiments.report import (
    intro,
    mechanisms,
    name_strategies,
    paper,
    strategy_definitions,
    tool_rule,
)
from experiments.report.batch_report import numbers_and_figures
from experiments.report.figures import FigureFile
from experiments.report.mechanism_figures import mechanism_figures
from experiments.report.pages import (
    Table,
    ci_text,
    num,
    p_value,
    pct,
    render,
    settings_table,
    shares_text,
    trials_table,
    where_table,
    write_page,
)
from experiments.report.summary import page_summary, summary_files

# Random arm commands behind the comparison's stick-grasp rates of the two backends.
GRASP_RATE_COMMANDS = 1000


def _sides(dir_a: Path, dir_b: Path) -> tuple[BatchResults, BatchResults]:
    """One group per side: two batches of one group each, or one batch of exactly two."""
    a = collect(dir_a)
    if dir_a.resolve() == dir_b.resolve():
        if len(a.groups) != 2:
            raise ReportError(
                f"{dir_a} holds {len(a.groups)} group(s) ({', '.join(a.groups)}): comparing a "
                "batch with itself needs exactly two groups"
            )
        return a.select(a.groups[0]), a.select(a.groups[1])
    b = collect(dir_b)
    for side, path in ((a, dir_a), (b, dir_b)):
        if len(side.groups) != 1:
            raise ReportError(
                f"{path} holds {len(side.groups)} groups ({', '.join(side.groups)}): a "
                "comparison takes one group per batch"
            )
    if a.groups == b.groups:  # two batches of the same backend: tell them apart by folder
        a = a.relabel({a.groups[0]: f"{a.groups[0]} ({dir_a.name})"})
        b = b.relabel({b.groups[0]: f"{b.groups[0]} ({dir_b.name})"})
    return a, b


def _per_iteration(cost: float) -> str:
    """Seconds per iteration as milliseconds, or why there is no number."""
    return "not recorded" if not np.isfinite(cost) else f"{1000 * cost:.2f} ms / iteration"


def _competence_rows(a: BatchResults, b: BatchResults) -> list[list[str]]:
    """Per scope: both sides' mean and interval, Welch's t test on the per-trial values."""
    rows = []
    summary = competence_summary(pd.concat([a.trials, b.trials]))
    for scope in COMPETENCE_SCOPES:
        values = [side.trials[f"competence_{scope}"].to_numpy() for side in (a, b)]
        texts = [
            ci_text(
                summary[(summary["group"] == s.groups[0]) & (summary["scope"] == scope)].iloc[0]
            )
            for s in (a, b)
        ]
        name = "all rings" if scope == "all" else scope.replace("ring", "ring ")
        rows.append(
            [
                f"Normalised competence, {name}",
                *texts,
                "Welch t (per-trial values)",
                p_value(welch(*values)[1]),
            ]
        )
    return rows


def _strategy_rows(a: BatchResults, b: BatchResults, geometry: Geometry) -> list[list[str]]:
    """Per region: both sides' shares, χ² test of groups × strategies on pooled counts."""
    rows = []
    tests = pd.concat([a.competence, b.competence])
    counts = strategy_counts(tests, geometry.hand_limit, geometry.stick_limit)
    shares = strategy_table(tests, geometry.hand_limit, geometry.stick_limit)
    for region in regions(geometry.hand_limit, geometry.stick_limit):
        table = counts[counts["region"] == region]
        texts = [
            shares_text(
                shares[(shares["group"] == s.groups[0]) & (shares["region"] == region)].iloc[0]
            )
            for s in (a, b)
        ]
        matrix = table.set_index("group").loc[[a.groups[0], b.groups[0]], list(STRATEGIES)]
        rows.append(
            [
                f"Strategy hand / tool / vocal, {region}",
                *texts,
                "χ² (pooled tests, groups × strategies)",
                p_value(chi_square(matrix.to_numpy())[1]),
            ]
        )
    return rows


# Per-trial stick numbers (experiments/analysis/curves.py): (column, statistic, how to show it).
STICK_NUMBERS = (
    ("stick_in_reach", "Iterations that began with the stick within reach", pct),
    ("stick_grasps_per_1000_arm", "Stick grasps per 1000 arm movements", num),
    ("toy_catches_per_1000_arm", "Toys caught with the stick per 1000 arm movements", num),
    ("stick_returns", "Stick returns by the experimenter per trial", num),
)


def _stick_rows(a: BatchResults, b: BatchResults, geometry: Geometry) -> list[list[str]]:
    """The stick as a tool: per-trial numbers (Welch), the tool tests split into stick held
    and stick only pushed (χ²), and how often random commands grasp it from its start."""
    rows = []
    for column, name, shown in STICK_NUMBERS:
        values = [s.trials[column].to_numpy(dtype=float) for s in (a, b)]
        if any(np.isnan(v).all() for v in values):
            continue  # logs written before the column existed
        texts = [f"{shown(np.nanmean(v))} (n={len(v)})" for v in values]
        rows.append([name, *texts, "Welch t (per-trial values)", p_value(welch(*values)[1])])
    tools = [s.competence[s.competence["strategy"] == "tool"] for s in (a, b)]
    if all("stick_grasped" in t.columns for t in tools):
        held = [int(t["stick_grasped"].sum()) for t in tools]
        pushed = [len(t) - h for t, h in zip(tools, held, strict=True)]
        texts = [f"{h} / {p}" for h, p in zip(held, pushed, strict=True)]
        p = chi_square(np.array([held, pushed]).T)[1]
        rows.append(
            ["Tool tests: stick held / only pushed", *texts, "χ² (pooled tests)", p_value(p)]
        )
    return rows


def _grasp_rate_row(
    a: BatchResults, b: BatchResults, n_commands: int, measures: RoomMeasures
) -> list[list[str]]:
    """The share of the same random arm commands that grasp the stick from its start pose in
    each side's backend (experiments/measure/stick.py), when the sides ran different backends
    (whichever: one backend would give both sides the same share)."""
    grasps = [str(s.trials["grasp"].iloc[0]) for s in (a, b)]
    if grasps[0] == grasps[1]:
        return []
    rates = measures.grasp_rates(n_commands, tuple(grasps))
    texts = [f"{pct(rates[g], 1)} of {n_commands}" for g in grasps]
    return [["Random arm commands that grasp the stick at its start", *texts, "same commands", ""]]


def _vocal_rows(a: BatchResults, b: BatchResults, threshold: float) -> list[list[str]]:
    """Share of words within the threshold (Fisher exact) and median best distances
    (Mann-Whitney U), on the words of every trial pooled."""
    below = [(s.vocal["best_distance"] < threshold).sum() for s in (a, b)]
    total = [len(s.vocal) for s in (a, b)]
    table = np.array([[below[0], total[0] - below[0]], [below[1], total[1] - below[1]]])
    fisher = stats.fisher_exact(table)
    rows = [
        [
            f"Words imitated within {threshold:g}",
            *[f"{pct(n / m if m else math.nan)} of {m}" for n, m in zip(below, total, strict=True)],
            "Fisher exact (pooled words)",
            p_value(float(fisher.pvalue)),
        ]
    ]
    for label, pick in (
        ("all words", lambda v: v),
        ("toy names", lambda v: v[v["is_name"]]),
        ("distractors", lambda v: v[~v["is_name"]]),
    ):
        values = [pick(s.vocal)["best_distance"].to_numpy(dtype=float) for s in (a, b)]
        rows.append(
            [
                f"Best word distance, {label} (median)",
                *[f"{num(np.median(v)) if len(v) else 'n/a'} (n={len(v)})" for v in values],
                "Mann-Whitney U (pooled words)",
                p_value(mann_whitney(*values)[1]),
            ]
        )
    return rows


def _cost_rows(a: BatchResults, b: BatchResults) -> list[list[str]]:
    """Diverged iterations (χ² on pooled iterations) and compute cost per iteration."""
    diverged = [int(s.trials["diverged"].sum()) for s in (a, b)]
    iterations = [int(s.trials["iterations"].sum()) for s in (a, b)]
    pairs = list(zip(diverged, iterations, strict=True))
    costs = [cost_per_iteration(s.trials) for s in (a, b)]
    ratio = costs[1] / costs[0] if all(np.isfinite(costs)) and costs[0] > 0 else math.nan
    return [
        [
            "Iterations whose physics diverged",
            *[f"{d} of {n}" for d, n in pairs],
            "χ² (pooled iterations)",
            p_value(chi_square(np.array([[d, n - d] for d, n in pairs]))[1]),
        ],
        [
            "Cost per iteration (timing.json: trial seconds / iterations)",
            *[_per_iteration(c) for c in costs],
            f"ratio {b.groups[0]} / {a.groups[0]}",
            "n/a" if not np.isfinite(ratio) else f"{ratio:.2f}×",
        ],
    ]


def difference_rows(
    a: BatchResults,
    b: BatchResults,
    geometry: Geometry,
    measures: RoomMeasures,
    grasp_rate_commands: int = GRASP_RATE_COMMANDS,
) -> list[list[str]]:
    """[statistic, A, B, test, p] rows: is the difference between the two groups real?
    `a`, `b`: one group each."""
    return [
        *_competence_rows(a, b),
        *_strategy_rows(a, b, geometry),
        *strategy_definitions.comparison_rows(a, b, geometry),
        *_vocal_rows(a, b, geometry.threshold),
        *_stick_rows(a, b, geometry),
        *tool_rule.comparison_rows(a, b),
        *_grasp_rate_row(a, b, grasp_rate_commands, measures),
        *_cost_rows(a, b),
        *mechanisms.comparison_rows(a, b),
    ]


def write_comparison(
    dir_a: str | os.PathLike,
    dir_b: str | os.PathLike,
    out_dir: str | os.PathLike,
    *,
    measures: RoomMeasures,
    grasp_rate_commands: int = GRASP_RATE_COMMANDS,
) -> Path:
    """Two batches (e.g. kinematic and physical grasping) side by side: every figure with one
    panel per batch, the paper table with both, tests of their differences and the cost per
    iteration of each, and the stick's numbers (with `grasp_rate_commands` random commands
    played in both backends). `dir_a` may equal `dir_b` for one batch of exactly two groups. Writes
    `comparison.html`, `comparison-*.png` and the page's numbers (`summary.json`,
    `summary.csv`: experiments/report/summary.py) into out_dir; returns the page's path."""
    dir_a, dir_b = Path(dir_a), Path(dir_b)
    a, b = _sides(dir_a, dir_b)
    check_out_dir(Path(out_dir))
    merged = a.merge(b)
    geometry, numbers, published, page_figures = numbers_and_figures(merged, measures)
    page_figures += mechanism_figures(merged, geometry)
    figures = [FigureFile(f"comparison-{f.name}", f.title, f.caption, f.png) for f in page_figures]
    g = merged.groups
    computed_on = provenance.short_record(provenance.machine_record())  # this page's machine
    where, where_note = where_table(merged, computed_on)
    tests = Table(
        ["statistic", g[0], g[1], "test of the difference", "p (two-sided)"],
        difference_rows(a, b, geometry, measures, grasp_rate_commands),
    )
    page = render(
        "comparison.html.j2",
        title=f"Playroom comparison: {g[0]} vs {g[1]}",
        figures=figures,
        n_a=len(a.trials),
        n_b=len(b.trials),
        # One directory when a batch is compared with itself.
        dirs=[str(d) for d in dict.fromkeys((dir_a, dir_b))],
        settings=settings_table(merged),
        configs=merged.configs,
        tests=tests,
        paper_table=paper.paper_table(merged, numbers, geometry, prefix=""),
        paper=published,
        reference=paper.reference(),
        trials=trials_table(merged),
        where=where,
        where_note=where_note,
        **name_strategies.page_context(merged, geometry.threshold),
        **tool_rule.page_context(merged),
        **intro.page_context(merged, geometry),
    )
    content = page_summary(
        merged,
        numbers,
        published,
        page=COMPARISON_FILE,
        batches=[str(d) for d in dict.fromkeys((dir_a, dir_b))],
        computed_on=computed_on,
        tests=tests,
    )
    # Both definitions of "tool", with intervals over trials (issue 32: like with like).
    for group, numbers_of in strategy_definitions.summary_numbers(merged, geometry).items():
        content["by_group"][group]["strategy_definitions"] = numbers_of
    return write_page(Path(out_dir), figures, COMPARISON_FILE, page, summary_files(content))
