"""Two batches side by side (`playroom compare DIR_A DIR_B --out DIR`): every figure with one
panel per side, the paper table with both, and tests of whether their differences are real.

A side is one group of trials: two batches of one group each (e.g. kinematic and physical
grasping run apart), or one batch of exactly two groups compared with itself. Every t of the
table of differences has a nonparametric p beside it, each kind Holm-adjusted over the page's
one family (experiments/report/differences.py), and the cells whose star differs between the
two are named; every trial's values are written beside the page (comparison-trials.csv,
experiments/report/comparison_data.py).
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from experiments.analysis.geometry import Geometry
from experiments.analysis.results import BatchResults, ReportError, check_out_dir, collect
from experiments.analysis.room_measures import RoomMeasures
from experiments.analysis.trial_tests import ALPHA
from experiments.analysis.trial_values import VALUE
from experiments.batch_files import COMPARISON_FILE
from experiments.report import (
    comparison_data,
    differences,
    intro,
    name_strategies,
    paper,
    strategy_definitions,
    tool_rule,
)
from experiments.report.backend_rules import backend_rules, rules_text
from experiments.report.batch_report import numbers_and_figures
from experiments.report.figures import FigureFile
from experiments.report.measures import registry
from experiments.report.mechanism_figures import mechanism_figures
from experiments.report.pages import (
    Table,
    p_value,
    pct,
    render,
    settings_table,
    trials_table,
    where_table,
    write_page,
)
from experiments.report.summary import page_summary, summary_files
from experiments.trial_dir import provenance

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
    # The same commands played in both rooms: a property of the rooms, not a sample of agents.
    test = "not tested: the same commands in both rooms, not a sample of trials"
    return [["Random arm commands that grasp the stick at its start", *texts, test, ""]]


def difference_table(
    a: BatchResults,
    b: BatchResults,
    geometry: Geometry,
    room: RoomMeasures,
    grasp_rate_commands: int = GRASP_RATE_COMMANDS,
) -> tuple[Table, list[differences.Evaluated]]:
    """The table of differences: every measure of the registry (experiments/report/
    measures.py) tested over trials (experiments/report/differences.py), then the random
    commands' grasp rates (the same commands in both rooms: not a sample of trials, not
    tested). `a`, `b`: one group each. Returns the table and the evaluated measures."""
    evaluated = differences.evaluate(registry(geometry), a, b)
    tested = sum(np.isfinite(o.test.p) for e in evaluated for o in e.outcomes)
    header = [
        "measure (mean over trials [95% t interval])",
        a.groups[0],
        b.groups[0],
        "test over trials",
        "p (two-sided)",
        f"survives Holm ({tested} tests, α = {ALPHA:g})",
        "nonparametric test beside it: p (two-sided)",
        f"its p survives Holm ({tested} tests, α = {ALPHA:g})",
    ]
    rows = differences.rows(evaluated, a, b)
    rows += [[*r, "", "", ""] for r in _grasp_rate_row(a, b, grasp_rate_commands, room)]
    return Table(header, rows), evaluated


def tests_note(evaluated: list[differences.Evaluated]) -> str:
    """The sentence under the table: how many tests it makes and how many survive Holm."""
    summary = differences.tests_summary(evaluated)
    # The tests of the two sides (not those of one side's gap against 0) pair or do not.
    paired = [t["paired"] for t in summary["tests"] if len(t["n"]) == 2]
    how = (
        "paired over seeds (both sides hold the same seeds)"
        if paired and all(paired)
        else "Welch's t (the sides do not hold the same seeds, so they do not pair)"
    )
    rank = (
        "the Wilcoxon signed-rank test of the same differences"
        if paired and all(paired)
        else "the Mann-Whitney U test of the same values"
    )
    return (
        f"This table makes {summary['count']} tests on per-trial values, {how}; "
        f"{summary['survive']} of them survive Holm's correction for that number "
        f"(family-wise α = {ALPHA:g}). Beside each t, a nonparametric test: {rank} (the "
        "signed-rank test of the values where a gap is tested against 0), Holm-adjusted over "
        f"the same tests: {summary['survive_rank']} survive. The family, fixed by the measures "
        f"and the sides before any value is compared: {differences.FAMILY}."
    )


def disagreement_lines(evaluated: list[differences.Evaluated]) -> list[str]:
    """Every cell whose Holm verdict differs between the t and the nonparametric test beside
    it, as a line naming the measure, the part and both ps."""
    lines = []
    for e in evaluated:
        for o in e.outcomes:
            if not np.isfinite(o.test.p) or o.survives == o.rank_survives:
                continue
            part = "" if o.part == VALUE else f", {o.part}"
            starred = "the t" if o.survives else o.test.rank_method
            lines.append(
                f"{e.measure.label}{part}: survives Holm with {starred} only "
                f"({o.test.method} {p_value(o.test.p)}; {o.test.rank_method} "
                f"{p_value(o.test.rank_p)})"
            )
    return lines


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
    `comparison.html`, `comparison-*.png`, the page's numbers (`summary.json`,
    `summary.csv`: experiments/report/summary.py) and every trial's values
    (`comparison-trials.csv`: experiments/report/comparison_data.py) into out_dir; returns the
    page's path."""
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
    tests, evaluated = difference_table(a, b, geometry, measures, grasp_rate_commands)
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
        backend_rules=rules_text(merged.configs),
        tests=tests,
        tests_note=tests_note(evaluated),
        disagreements=disagreement_lines(evaluated),
        trials_file=comparison_data.FILE,
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
        evaluated=evaluated,
        registry=registry(geometry),
    )
    content["backend_rules"] = backend_rules(merged.configs)
    # Both definitions of "tool", with intervals over trials (like with like).
    for group, numbers_of in strategy_definitions.summary_numbers(merged, geometry).items():
        content["by_group"][group]["strategy_definitions"] = numbers_of
    beside = summary_files(content)
    trials = comparison_data.trial_table(evaluated, a, b)
    beside[comparison_data.FILE] = trials.to_csv(index=False).encode()
    return write_page(Path(out_dir), figures, COMPARISON_FILE, page, beside)
