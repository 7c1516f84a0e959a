"""Ablations: batches that differ from a baseline batch by a setting or two, compared trial by
trial (`playroom ablations BASELINE BATCH [BATCH ...] --out DIR`).

Each row is one group of one batch (a batch of one backend has one group) set against the
baseline's group of the same name, on the seeds both hold: the comparison is paired by seed,
so a difference is a difference of settings, not of random draws. The baseline row is the
baseline restricted to the seeds the ablation batches hold (e.g. seeds 0-31 of a 100-seed
replication). A row is labelled by what its settings change from the baseline's, read from the
trials' config.json, so the table cannot name a setting that was not changed.

Numbers per row: the competence and strategy shares as the study computed them
(experiments.measure.study_measure); the measures of the registry marked for this table
(experiments/report/measures.py: the project's competence, each trial's share of words
imitated within the recognition distance, each trial's gap between its distractors and its
names), each a mean over the row's trials with the mean paired difference from the baseline
(95% interval, paired t test over seeds, two-sided, the Wilcoxon signed-rank p beside it), the
gap also against 0 within the row; Holm's correction over the table's one family of tests, for
each kind of p (experiments/report/ablation_tests.py). Then, as the study reported them, the
median best distance of the pooled names and distractors and their Mann-Whitney test on the
pooled words, its p two-sided as the study computed it (the one-sided p doubled): a second
line, which treats words as independent. Written: ablations.md (the table, its family of tests
and the cells whose star differs between the two tests: experiments/report/ablation_page.py),
ablations.csv (every number, unrounded), ablations-trials.csv (every trial's values and who
computed it: experiments/report/ablation_data.py), ablations.png (the paired differences and
the names effect, one line per row).
"""

from __future__ import annotations

import math
import os
import re
import textwrap
from dataclasses import asdict, replace
from pathlib import Path

import pandas as pd
from matplotlib.figure import Figure

from experiments.analysis.geometry import Geometry
from experiments.analysis.results import BatchResults, ReportError, check_out_dir, collect
from experiments.analysis.room_measures import RoomMeasures
from experiments.analysis.stats import STRATEGIES, vocal_summary
from experiments.batch_files import ABLATION_CSV_FILE, ABLATION_FIGURE_FILE, ABLATION_TABLE_FILE
from experiments.report import ablation_data, ablation_tests, paper
from experiments.report.ablation_page import STUDY_REGIONS, markdown
from experiments.report.ablation_tests import AblationRow
from experiments.report.figures import STRATEGY_COLOURS, png_bytes
from experiments.report.measures import Measure, registry
from experiments.report.pages import pct
from experiments.trial_dir import storage
from experiments.trial_dir.config_file import config_differences

# How a batch recorded its settings' origin, not a setting: left out of the rows' labels.
BOOKKEEPING = ("trial.preset", "trial.overrides")
# The world's copies of trial settings: a row says "trial.voice: vtl -> diva" once, not twice.
MIRRORED = ("world.stick_return", "world.voice")
# The measure whose paired differences the figure's left panel draws.
COMPETENCE = "competence_all"


def describe_change(baseline: dict, config: dict) -> str:
    """The settings that differ between two group configs, as `key: before -> after`."""
    changes = [
        change
        for change in config_differences(baseline, config)
        if not any(change[0] == key or change[0].startswith(f"{key}.") for key in BOOKKEEPING)
        and change[0] not in MIRRORED
    ]
    if not changes:
        return "the baseline's settings"
    return "; ".join(f"{key}: {before} -> {after}" for key, before, after in changes)


def _row(
    results: BatchResults,
    group: str,
    label: str,
    room: RoomMeasures,
    measures: tuple[Measure, ...],
    baseline: BatchResults | None,
) -> AblationRow:
    results = results.select(group)
    study = room.study_numbers(results).get(group)
    summary = vocal_summary(results.vocal, Geometry.of(results).threshold)
    theirs = baseline.select(group) if baseline is not None else None
    return AblationRow(
        label=label,
        batch=results.batch_dir.name,
        group=group,
        n_trials=len(results.trials),
        study_competence=study["competence"]["all"] if study else math.nan,
        study_strategies=study["strategy_share"] if study else {},
        measures={m.name: ablation_tests.numbers(m, results, theirs) for m in measures},
        median_names=summary["median_names"],
        median_distractors=summary["median_distractors"],
        pooled_names_vs_distractors_p_two_sided=summary["p"],
    )


def ablation_rows(
    baseline_dir: str | os.PathLike,
    batch_dirs: list[str | os.PathLike],
    measures: RoomMeasures,
) -> list[AblationRow]:
    """The baseline's row first, then one row per group of each batch that the baseline also
    holds, with Holm's adjustment over the table's tests. ReportError (one line) for a batch
    that cannot be read or shares no group and no seed with the baseline."""
    return _rows_and_measures(*_read(baseline_dir, batch_dirs), measures)[0]


def _read(
    baseline_dir: str | os.PathLike, batch_dirs: list[str | os.PathLike]
) -> tuple[BatchResults, list[BatchResults]]:
    if not batch_dirs:
        raise ReportError("give at least one batch to compare with the baseline")
    return collect(baseline_dir), [collect(d) for d in batch_dirs]


def _rows_and_measures(
    baseline: BatchResults, batches: list[BatchResults], room: RoomMeasures
) -> tuple[list[AblationRow], tuple[Measure, ...], pd.DataFrame]:
    """The rows, the table's measures and every row's trials (ablation_data)."""
    seeds: set[int] = set()
    pairs = []
    for results in batches:
        groups = [g for g in results.groups if g in baseline.groups]
        if not groups:
            raise ReportError(
                f"{results.batch_dir} holds groups {results.groups}, the baseline "
                f"{baseline.groups}: none in common"
            )
        mine = set(results.trials["seed"])
        if not mine & set(baseline.trials["seed"]):
            raise ReportError(f"{results.batch_dir} shares no seed with the baseline")
        seeds |= mine
        pairs += [(results, g) for g in groups]
    baseline = baseline.with_seeds(seeds)
    measures = ablation_tests.ablation_measures(registry(Geometry.of(baseline)))
    label = f"baseline ({baseline.batch_dir.name})"
    shared = [g for g in baseline.groups if any(g == group for _, group in pairs)]
    rows = [_row(baseline, g, label, room, measures, None) for g in shared]
    trials = [ablation_data.row_trials(baseline.select(g), label, True, measures) for g in shared]
    several = len(baseline.groups) > 1
    for results, group in pairs:
        label = describe_change(baseline.configs[group], results.configs[group])
        label = f"{label} [{group}]" if several else label
        rows.append(_row(results, group, label, room, measures, baseline))
        trials.append(ablation_data.row_trials(results.select(group), label, False, measures))
    adjusted = ablation_tests.with_holm([row.measures for row in rows], measures)
    rows = [replace(r, measures=m) for r, m in zip(rows, adjusted, strict=True)]
    return rows, measures, ablation_data.trial_table(trials)


def csv_table(rows: list[AblationRow]) -> pd.DataFrame:
    """Every number of the rows, one column each (strategy shares and measures flattened:
    `<measure>_<number>`)."""
    records = []
    for row in rows:
        record = asdict(row)
        shares = record.pop("study_strategies")
        for name, numbers in record.pop("measures").items():
            record.update({f"{name}_{k}": v for k, v in numbers.items()})
        for region in STUDY_REGIONS:
            for strategy in STRATEGIES:
                record[f"study_{region}_{strategy}"] = shares.get(region, {}).get(
                    strategy, math.nan
                )
        records.append(record)
    return pd.DataFrame(records)


# The study's regions in words, for the figure's legends.
REGION_WORDS = {"centre": "centre", "between_limits": "between limits", "distance_1": "distance 1"}
# The paper's vocal shares per study region (experiments/report/data/paper.json's keys).
PAPER_VOCAL = {
    "centre": "strategy_centre",
    "between_limits": "strategy_between_limits",
    "distance_1": "strategy_distance_1",
}
# A setting's dotted key ("learner.exploration_sigma"): its part ("learner") and its name.
_KEY = re.compile(r"\b([a-z]\w*)\.([a-z][\w.]*)")


def figure_label(label: str) -> str:
    """A row's label in words for the figure: "learner.exploration_sigma: 0.05 -> 0.1" reads
    "exploration sigma (learner): 0.05 → 0.1"; the table and the CSV keep the dotted keys
    (they name the settings exactly, for `--set`)."""
    words = _KEY.sub(lambda m: f"{m.group(2).split('.')[-1]} ({m.group(1)})", label)
    return words.replace("_", " ").replace(" -> ", " → ")


def _draw_paper(middle, right) -> None:
    """The paper's numbers as references: the vocal share of each region (a band where it
    gives a range) and the medians of names and distractors."""
    published = paper.published()
    for (region, key), style in zip(PAPER_VOCAL.items(), ("/", "\\", "-"), strict=True):
        value = published[key].value["vocal"]
        low, high = (value, value) if isinstance(value, float) else value
        label = f"paper, {REGION_WORDS[region]}: {pct(low)}" + (
            f"–{pct(high)}" if high != low else ""
        )
        if high == low:
            middle.axvline(100 * low, color="0.4", ls="--", lw=1, label=label)
        else:
            middle.axvspan(100 * low, 100 * high, color="0.85", hatch=style, alpha=0.6, label=label)
    for key, colour, words in (
        ("median_names", "tab:purple", "names"),
        ("median_distractors", "tab:grey", "distractors"),
    ):
        value = published[key].value
        right.axvline(value, color=colour, ls=":", lw=1.5, label=f"paper, {words}: {value:g}")


def ablation_figure(rows: list[AblationRow]) -> Figure:
    """Left: the paired difference of the project's competence from the baseline, with its 95%
    interval. Middle: the vocal share of each study region. Right: the names effect. The
    paper's numbers are drawn where it gives some; labels are in words."""
    fig = Figure(figsize=(15, 0.7 * len(rows) + 3.2), layout="constrained")
    left, middle, right = fig.subplots(1, 3, sharey=True)
    y = list(range(len(rows)))[::-1]
    _draw_paper(middle, right)
    for yi, row in zip(y, rows, strict=True):
        competence = row.measures.get(COMPETENCE)
        if competence is not None and math.isfinite(competence.difference):
            left.errorbar(
                100 * competence.difference,
                yi,
                xerr=[
                    [100 * (competence.difference - competence.low)],
                    [100 * (competence.high - competence.difference)],
                ],
                fmt="o",
                color="black",
                capsize=3,
            )
        for marker, region in zip("o^s", STUDY_REGIONS, strict=True):
            share = row.study_strategies.get(region, {}).get("vocal", math.nan)
            middle.plot(
                100 * share, yi, marker, color=STRATEGY_COLOURS["vocal"], label=REGION_WORDS[region]
            )
        right.plot(row.median_names, yi, "o", color="tab:purple", label="toy names")
        right.plot(row.median_distractors, yi, "x", color="tab:grey", label="distractors")
    left.axvline(0.0, color="grey", linewidth=0.8)
    labels = [textwrap.fill(figure_label(row.label), 50) for row in rows]
    left.set_yticks(y, labels, fontsize=8)
    left.set_xlabel(
        "competence, project's measure: difference\nfrom the baseline (percentage points, 95% CI)"
    )
    middle.set_xlabel("vocal strategy share, study's measure (%)")
    middle.set_xlim(left=0)
    right.set_xlabel("median best distance of words (log2 Hz)\n(lower is better)")
    for axis in (middle, right):
        handles, names = axis.get_legend_handles_labels()
        unique = dict(zip(names, handles, strict=True))
        axis.legend(
            unique.values(),
            unique.keys(),
            fontsize=7,
            loc="lower left",
            bbox_to_anchor=(0.0, 1.0),
            ncols=2,
            frameon=False,
        )
    n = rows[0].n_trials if rows else 0
    fig.suptitle(
        "Ablations: each configuration against the baseline, paired by seed "
        f"(baseline: {n} trials); grey and dotted: the paper's values"
    )
    return fig


def ablation_files(
    baseline: BatchResults, batches: list[BatchResults], room: RoomMeasures
) -> dict[str, bytes]:
    """Every file of the table (the table last) from the baseline's and the batches' results."""
    rows, columns, trials = _rows_and_measures(baseline, batches, room)
    return {
        ABLATION_CSV_FILE: csv_table(rows).to_csv(index=False).encode(),
        ablation_data.FILE: trials.to_csv(index=False).encode(),
        ABLATION_FIGURE_FILE: png_bytes(ablation_figure(rows)),
        ABLATION_TABLE_FILE: markdown(rows, columns).encode(),
    }


def write_ablations(
    baseline_dir: str | os.PathLike,
    batch_dirs: list[str | os.PathLike],
    out_dir: str | os.PathLike,
    *,
    measures: RoomMeasures,
) -> Path:
    """Compute the rows, then write the CSV, the per-trial data, the figure and the table into
    out_dir as one unit (after everything was computed; a failed write leaves nothing). Returns
    the table's path."""
    check_out_dir(Path(out_dir))
    files = ablation_files(*_read(baseline_dir, batch_dirs), measures)
    return storage.write_files(Path(out_dir), files)[-1]
