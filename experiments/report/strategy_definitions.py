"""The strategy shares of a comparison under both definitions of "tool" (the study's: the stick
moved; and the stick held), for the project's tests and the study's, with intervals over
trials (experiments/analysis/strategies.py): `strategy_definitions` in summary.json. The rows
of the comparison's table of differences are measures of experiments/report/measures.py."""

from __future__ import annotations

from typing import Any

import pandas as pd

from experiments.analysis.geometry import Geometry
from experiments.analysis.results import BatchResults
from experiments.analysis.stats import regions
from experiments.analysis.strategies import both_definitions, contact_counts

# The two sets of tests each trial holds: the project's measure (every test from the same
# scene) and the study's (the scene carried over), named as the pages name them.
MEASURES = {"project": "competence", "study": "study_tests"}


def shares(results: BatchResults, geometry: Geometry) -> pd.DataFrame:
    """`both_definitions` of each measure's tests, with a `measure` column."""
    tables = []
    areas = regions(geometry.hand_limit, geometry.stick_limit)
    for measure, attribute in MEASURES.items():
        tests = getattr(results, attribute)
        if tests.empty or "strategy" not in tests.columns:
            continue
        tables.append(both_definitions(tests, areas).assign(measure=measure))
    return pd.concat(tables, ignore_index=True) if tables else pd.DataFrame()


def summary_numbers(results: BatchResults, geometry: Geometry) -> dict[str, Any]:
    """group -> measure -> definition -> region -> strategy -> {mean, low, high}, with n_trials
    and n_tests per region; and group -> contacts (arm tests by stick contact, tests by what
    moved the goal toy) per measure."""
    table = shares(results, geometry)
    out: dict[str, Any] = {}
    for (group, measure, definition, region), rows in (
        table.groupby(["group", "measure", "definition", "region"], sort=False)
        if not table.empty
        else []
    ):
        node = out.setdefault(str(group), {}).setdefault(str(measure), {})
        node = node.setdefault(str(definition), {})
        node[region] = {
            **{
                r["strategy"]: {k: float(r[k]) for k in ("mean", "low", "high", "count")}
                for _, r in rows.iterrows()
            },
            "n_trials": int(rows["n_trials"].iloc[0]),
            "n_tests": int(rows["n_tests"].iloc[0]),
        }
    for measure, attribute in MEASURES.items():
        tests = getattr(results, attribute)
        if tests.empty:
            continue
        for _, r in contact_counts(tests).iterrows():
            node = out.setdefault(r["group"], {}).setdefault("contacts", {})
            node.setdefault(measure, {}).setdefault(r["what"], {})[r["value"]] = int(r["count"])
    return out
