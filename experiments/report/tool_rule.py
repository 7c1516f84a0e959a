"""The study's tool rule beside a minimum motion of the stick, on both pages.

The study counted a test as tool use when the stick's x differed at all between the first and
the last sample of the movement (experiments/measure/study_measure.py). With contacts, the
physical stick is nudged by fractions of a millimetre that no one would call tool use; the
pages keep the study's rule as the measure and show beside it how many of its tool uses moved
the stick less than `TOOL_MIN_MOTION`, and the tool share without them
(experiments/analysis/stats.py, `tool_motion`). The comparison's rows of these numbers, per
trial and tested over trials, are measures of experiments/report/measures.py.
"""

from __future__ import annotations

import math

from experiments.analysis.results import BatchResults
from experiments.analysis.stats import TOOL_MIN_MOTION, tool_motion
from experiments.report.pages import Table, pct

NOT_RECORDED = (
    "not recorded: trials evaluated before the study's tests kept the stick's motion; "
    "`playroom eval` them again"
)


def _minimum_text(min_motion: float) -> str:
    return f"{1000 * min_motion:g} mm"


def _small_text(row: dict) -> str:
    return "not recorded" if math.isnan(row["small"]) else f"{int(row['small'])} of {row['tool']}"


def tool_motion_table(results: BatchResults, min_motion: float = TOOL_MIN_MOTION) -> Table | None:
    """Per group with study tests: tests, tool uses by the study's rule, those that moved the
    stick's x less than `min_motion`, and the tool share by either rule. None without tests."""
    if results.study_tests.empty:
        return None
    minimum = _minimum_text(min_motion)
    header = [
        "group",
        "study's tests",
        "tool uses (study's rule: the stick's x changed)",
        f"of which the stick's x moved less than {minimum}",
        "tool share, study's rule",
        f"tool share, at least {minimum}",
    ]
    rows = [
        [
            row["group"],
            str(row["tests"]),
            str(row["tool"]),
            _small_text(row),
            pct(row["tool_share"], 1),
            pct(row["tool_share_min_motion"], 1),
        ]
        for row in tool_motion(results.study_tests, min_motion).to_dict("records")
    ]
    return Table(header, rows)


def page_context(results: BatchResults) -> dict:
    """What the pages' "Tool use and a minimum motion" section reads (macros.html.j2)."""
    return {
        "tool_motion": tool_motion_table(results),
        "tool_min_motion": _minimum_text(TOOL_MIN_MOTION),
        "tool_motion_note": NOT_RECORDED,
    }
