"""summary.json and summary.csv (experiments/report/summary.py): numbers the page shows as
"n/a" are null and empty, never NaN, and the CSV is the JSON's per-group numbers. That a
summary holds its page's numbers is checked on the pages tests/report/test_report.py writes."""

from __future__ import annotations

import io
import json
import math

import pandas as pd

from experiments.batch_files import SUMMARY_CSV_FILE, SUMMARY_JSON_FILE
from experiments.report.summary import CSV_COLUMNS, summary_files


def test_numbers_without_a_value_are_null_in_json_and_empty_in_csv():
    by_group = {
        "physical": {
            "trials": 1,
            "seeds": [0],
            "competence": {"all": {"mean": 0.25, "low": math.nan, "high": math.nan, "n": 1}},
            "strategies": {"centre": {"hand": 0.5, "tool": 0.0, "vocal": 0.5, "n": 4}},
            "vocal": {"n_words": 6, "share_below": 0.5, "median_names": math.inf, "p": 0.2},
            "study": {
                "competence": {"all": 0.1, "ring1": 0.2},
                "strategy_share": {"centre": {"hand": 1.0, "tool": 0.0, "vocal": 0.0}},
                "intervals": {"competence_all": [0.05, 0.15], "strategy_share": {}},
                "coverage": 0.5,
            },
        }
    }
    files = summary_files({"page": "report.html", "by_group": by_group})
    content = json.loads(files[SUMMARY_JSON_FILE])  # standard JSON: NaN would not parse back
    assert content["by_group"]["physical"]["competence"]["all"]["low"] is None
    assert content["by_group"]["physical"]["vocal"]["median_names"] is None
    table = pd.read_csv(io.BytesIO(files[SUMMARY_CSV_FILE]))
    assert list(table.columns) == CSV_COLUMNS
    rows = table.set_index(["measure", "statistic", "scope"])
    assert rows.loc[("project", "competence", "all"), "value"] == 0.25
    assert math.isnan(rows.loc[("project", "competence", "all"), "low"])
    assert math.isnan(rows.loc[("project", "median_names", math.nan), "value"])
    assert rows.loc[("project", "share_vocal", "centre"), "n"] == 4
    assert rows.loc[("study", "competence", "all"), "high"] == 0.15
    assert math.isnan(rows.loc[("study", "competence", "ring1"), "low"])
    assert rows.loc[("study", "coverage", math.nan), "value"] == 0.5
