"""A table of differences quoted in docs/ comes out of a comparison's summary.json by one
command (experiments/report/summary_rows.py)."""

import pytest

from experiments.report.summary_rows import markdown_rows

SUMMARY = {
    "tests": {
        "columns": ["measure", "kinematic", "physical", "test", "p"],
        "rows": [
            ["Normalised competence, all rings", "16.8%", "9.7%", "paired t", "p = 4.6e-08"],
            ["└ the same, pooled over tests", "", "", "χ²", "p < 1e-300"],
            ["Stick grasps per 1000 arm movements", "301.4", "155.2", "paired t", "p = 1e-28"],
        ],
    }
}


def test_the_rows_of_the_measures_asked_for_in_the_pages_order():
    text = markdown_rows(SUMMARY, ["Stick grasps", "Normalised competence"])
    lines = text.splitlines()
    assert lines[0] == "| measure | kinematic | physical | test | p |"
    assert [line.split(" | ")[0] for line in lines[2:]] == [
        "| Normalised competence, all rings",
        "| Stick grasps per 1000 arm movements",
    ]


def test_a_summary_without_a_table_of_differences_is_named():
    with pytest.raises(ValueError, match="no table of differences"):
        markdown_rows({"page": "report.html"}, [])
