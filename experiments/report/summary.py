"""The numbers a report or comparison page shows, machine-readable: `summary.json` and
`summary.csv`, written beside the page and with it, as one unit (pages.write_page).

Every fraction is a fraction (0.46, not 46%), every distance in the words' normalised units, and
a number the page shows as "n/a" (NaN, or a distance never reached) is null in the JSON and
empty in the CSV.

summary.json:
- page, batches (the batch directories read), groups (in the page's order);
- computed_on: the machine and libraries that computed the page's statistics (provenance's
  short record): a bootstrap interval's last digits follow its BLAS kernel;
- per group (`by_group`): trials, seeds; `competence` per scope (all, ring1..3: the project's
  normalised competence, mean over trials with its 95% interval and n trials); `strategies`
  per region (centre, between limits, distance 1: shares of hand, tool, vocal and n tests);
  `vocal` (n_words, share_below the recognition threshold, median_names, median_distractors,
  the names-vs-distractors Mann-Whitney u and two-sided p); `study` (the study's own measure,
  as the page's "as the study computed it" rows: competence per ring, strategy shares per
  region, coverage, bootstrap intervals where computed, reference_commands_per_ring), absent
  where it was not measured;
- trials: one record per trial (its competence per scope, vocal numbers, diverged iterations,
  stick numbers, seconds and timed iterations);
- paper: the paper's published numbers beside them (value, text, runs, source);
- measures: each measure of the registry (experiments/report/measures.py) the batch recorded:
  label, kind, parts, how it is tested, and `per_trial`, its value per trial as columns
  (trial, group, seed, one list of numbers per part);
- comparison pages only: `tests`, the page's table of differences as it shows it, text:
  columns (measure, each side's group, the test, its p, Holm) and rows; `trial_tests`, every
  test of it over trials (measure, part, method, statistic, difference, p, n per group,
  paired, Holm-adjusted p, survives; with the correction, alpha, count and survivors), the
  pooled second lines (`pooled`) and the parts not tested and why (`not_tested`).

summary.csv holds the per-group numbers as one long table, a row per number: group, measure
("project" or "study"), statistic, scope (ring or region, or empty), value, low, high, n.
"""

from __future__ import annotations

import io
import math
from typing import Any

import numpy as np
import pandas as pd

from experiments.analysis.mechanisms import LABELS
from experiments.analysis.results import BatchResults
from experiments.analysis.stats import STRATEGIES
from experiments.analysis.trial_rows import COMPETENCE_SCOPES
from experiments.batch_files import SUMMARY_CSV_FILE, SUMMARY_JSON_FILE
from experiments.report.differences import Evaluated, per_trial_values, tests_summary
from experiments.report.measures import Measure
from experiments.report.pages import Table
from experiments.report.paper import PaperNumber
from experiments.trial_dir import storage

CSV_COLUMNS = ["group", "measure", "statistic", "scope", "value", "low", "high", "n"]
# Per-trial numbers of BatchResults.trials kept in the summary, beside its trial and group.
TRIAL_NUMBERS = (
    "seed",
    *(f"competence_{k}" for k in COMPETENCE_SCOPES),
    "share_below_threshold",
    "median_names",
    "median_distractors",
    "diverged",
    "stick_in_reach",
    "stick_grasps_per_1000_arm",
    "toy_catches_per_1000_arm",
    "stick_returns",
    "seconds",
    "timed_iterations",
    *LABELS,  # what the logs say of the mechanisms (experiments/analysis/mechanisms.py)
)


def _number(x: Any) -> Any:
    """A plain Python number (NumPy's to int or float); NaN and inf stay for finite_or_null."""
    if isinstance(x, bool | np.bool_):
        return bool(x)
    if isinstance(x, np.integer):
        return int(x)
    if isinstance(x, np.floating):
        return float(x)
    return x


def _group_numbers(results: BatchResults, numbers: dict, group: str) -> dict[str, Any]:
    comp, strat = numbers["competence"], numbers["strategies"]
    trials = results.trials[results.trials["group"] == group]
    out: dict[str, Any] = {
        "trials": len(trials),
        "seeds": sorted(int(s) for s in trials["seed"]),
        "competence": {
            row["scope"]: {k: _number(row[k]) for k in ("mean", "low", "high", "n")}
            for _, row in comp[comp["group"] == group].iterrows()
        },
        "strategies": {
            row["region"]: {k: _number(row[k]) for k in (*STRATEGIES, "n")}
            for _, row in strat[strat["group"] == group].iterrows()
        },
        "vocal": {k: _number(v) for k, v in numbers["vocal"][group].items()},
    }
    study = numbers.get("study", {}).get(group)
    if study is not None:
        out["study"] = study
    return out


def _trial_records(results: BatchResults) -> list[dict[str, Any]]:
    kept = [c for c in TRIAL_NUMBERS if c in results.trials.columns]
    return [
        {"trial": row["trial"], "group": row["group"], **{c: _number(row[c]) for c in kept}}
        for _, row in results.trials.iterrows()
    ]


def _paper(published: dict[str, PaperNumber]) -> dict[str, Any]:
    return {
        key: {"value": n.value, "text": n.text, "runs": n.runs, "source": n.source}
        for key, n in published.items()
    }


def page_summary(
    results: BatchResults,
    numbers: dict,
    published: dict[str, PaperNumber],
    page: str,
    batches: list[str],
    computed_on: dict[str, str] | None,
    registry: tuple[Measure, ...],
    tests: Table | None = None,
    evaluated: list[Evaluated] | None = None,
) -> dict[str, Any]:
    """The summary of a page (module docstring), JSON-ready but for NaN and inf.
    `numbers`: what batch_report.numbers_and_figures computed for the page; `registry`: the
    measures whose per-trial values it holds; `evaluated`: a comparison's tests of them."""
    out: dict[str, Any] = {
        "page": page,
        "batches": batches,
        "computed_on": computed_on,
        "groups": list(results.groups),
        "by_group": {g: _group_numbers(results, numbers, g) for g in results.groups},
        "trials": _trial_records(results),
        "paper": _paper(published),
        "measures": per_trial_values(registry, results),
    }
    if tests is not None:
        out["tests"] = {"columns": tests.header, "rows": tests.rows}
    if evaluated is not None:
        out["trial_tests"] = tests_summary(evaluated)
    return out


def _row(group: str, measure: str, statistic: str, scope: str, value: Any, **extra) -> dict:
    return {
        "group": group,
        "measure": measure,
        "statistic": statistic,
        "scope": scope,
        "value": value,
        **extra,
    }


def csv_rows(by_group: dict[str, dict]) -> pd.DataFrame:
    """The per-group numbers of a summary as the long table of summary.csv."""
    rows = []
    for group, g in by_group.items():
        for scope, c in g["competence"].items():
            rows.append(
                _row(group, "project", "competence", scope, c["mean"], **_bounds(c), n=c["n"])
            )
        for region, s in g["strategies"].items():
            for strategy in STRATEGIES:
                rows.append(
                    _row(group, "project", f"share_{strategy}", region, s[strategy], n=s["n"])
                )
        vocal = g["vocal"]
        for key, value in vocal.items():
            if key != "n_words":
                rows.append(_row(group, "project", key, "", value, n=vocal.get("n_words")))
        study = g.get("study")
        if study is None:
            continue
        intervals = study.get("intervals", {})
        for scope, value in study["competence"].items():
            bounds = intervals.get(f"competence_{scope}") if scope == "all" else None
            rows.append(_row(group, "study", "competence", scope, value, **_pair(bounds)))
        for region, shares in study["strategy_share"].items():
            for strategy, value in shares.items():
                bounds = intervals.get("strategy_share", {}).get(region, {}).get(strategy)
                rows.append(
                    _row(group, "study", f"share_{strategy}", region, value, **_pair(bounds))
                )
        for key in ("coverage", "reference_commands_per_ring"):
            if key in study:
                rows.append(_row(group, "study", key, "", study[key]))
    return pd.DataFrame(rows, columns=CSV_COLUMNS)


def _bounds(numbers: dict) -> dict:
    return {"low": numbers["low"], "high": numbers["high"]}


def _pair(bounds: list[float] | None) -> dict:
    return {} if bounds is None else {"low": bounds[0], "high": bounds[1]}


def summary_files(content: dict[str, Any]) -> dict[str, bytes]:
    """summary.json and summary.csv of a `summary`, as bytes to write with the page."""
    table = csv_rows(content["by_group"])
    buffer = io.StringIO()
    # Infinite distances (a word never approached) are "n/a" on the page: empty here too.
    table.replace([math.inf, -math.inf], np.nan).to_csv(buffer, index=False)
    return {
        SUMMARY_JSON_FILE: storage.json_bytes(storage.finite_or_null(content)),
        SUMMARY_CSV_FILE: buffer.getvalue().encode("utf-8"),
    }
