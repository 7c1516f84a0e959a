"""The report of a batch of trials: its results beside the paper's (`playroom report DIR`);
two batches side by side are experiments/report/comparison.py's.

The work is split by job: `analysis.results` reads a batch directory into tables,
`analysis.stats` computes on them, `paper` holds the paper's published numbers, `figures`
draws, and `pages` renders the page from templates. Everything is computed and rendered in memory
first and the files are then written as one unit (`storage.write_files`), so a failing report
(bad input, a full disk) leaves nothing behind.
"""

from __future__ import annotations

import os
from pathlib import Path

from experiments.analysis.geometry import Geometry
from experiments.analysis.results import BatchResults, check_out_dir, collect
from experiments.analysis.room_measures import RoomMeasures
from experiments.analysis.stats import summarise_batch
from experiments.batch_files import REPORT_FILE
from experiments.report import intro, name_strategies, paper, tool_rule
from experiments.report.figures import FigureFile, report_figures
from experiments.report.measures import registry
from experiments.report.pages import render, settings_table, trials_table, where_table, write_page
from experiments.report.study_figures import study_figure_files
from experiments.report.summary import page_summary, summary_files
from experiments.trial_dir import provenance


def write_report(
    batch_dir: str | os.PathLike,
    out_dir: str | os.PathLike | None = None,
    *,
    measures: RoomMeasures,
) -> Path:
    """Figures (PNG) and `report.html` of a batch, its numbers beside the paper's, with the
    page's numbers in `summary.json` and `summary.csv` (experiments/report/summary.py); into
    `out_dir` (default: the batch directory). Returns the path of report.html. ReportError
    (one line) for a batch that cannot be reported on; nothing is written then.
    `measures`: the study's numbers, measured in rooms (experiments.measure.for_reports)."""
    results = collect(batch_dir)
    out = Path(out_dir) if out_dir is not None else results.batch_dir
    check_out_dir(out)
    geometry, numbers, published, figures = numbers_and_figures(results, measures)
    # Where this page's statistics are computed: said on the page and in its summary.
    computed_on = provenance.short_record(provenance.machine_record())
    where, where_note = where_table(results, computed_on)
    page = render(
        "report.html.j2",
        title=f"Playroom batch report: {results.batch_dir.name}",
        figures=figures,
        n_trials=len(results.trials),
        batch_dir=str(results.batch_dir),
        settings=settings_table(results),
        configs=results.configs,
        paper_table=paper.paper_table(results, numbers, geometry, prefix="this batch: "),
        paper=published,
        reference=paper.reference(),
        trials=trials_table(results),
        where=where,
        where_note=where_note,
        **name_strategies.page_context(results, geometry.threshold),
        **tool_rule.page_context(results),
        **intro.page_context(results, geometry),
    )
    content = page_summary(
        results,
        numbers,
        published,
        page=REPORT_FILE,
        batches=[str(results.batch_dir)],
        computed_on=computed_on,
        registry=registry(geometry),
    )
    return write_page(out, figures, REPORT_FILE, page, beside=summary_files(content))


def numbers_and_figures(
    results: BatchResults, measures: RoomMeasures
) -> tuple[Geometry, dict, dict[str, paper.PaperNumber], list[FigureFile]]:
    """What every page of results shows: its geometry, its numbers (the study's among them,
    from `measures`), the paper's published numbers and the figures (the study's Fig. 4
    included)."""
    geometry = Geometry.of(results)
    numbers = summarise_batch(results, geometry)
    numbers["study"] = measures.study_numbers(results)
    published = paper.published()
    figures = report_figures(results, geometry, published["competence_all"].value)
    figures += study_figure_files(results, published)
    return geometry, numbers, published, figures
