"""The study's tool rule beside a minimum motion of the stick, on both pages.

The study counted a test as tool use when the stick's x differed at all between the first and
the last sample of the movement (experiments/measure/study_measure.py). With contacts, the
physical stick is nudged by fractions of a millimetre that no one would call tool use; the
pages keep the study's rule as the measure and show beside it how many of its tool uses moved
the stick less than `TOOL_MIN_MOTION`, and the tool share without them
(experiments/analysis/stats.py, `tool_motion`).
"""

from __future__ import annotations

import math

import numpy as np

from experiments.analysis.results import BatchResults
from experiments.analysis.stats import TOOL_MIN_MOTION, chi_square, tool_motion
from experiments.report.pages import Table, p_value, pct

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


def comparison_rows(
    a: BatchResults, b: BatchResults, min_motion: float = TOOL_MIN_MOTION
) -> list[list[str]]:
    """[statistic, A, B, test, p] rows of the comparison: the study's tool uses that moved the
    stick less than `min_motion`, and the tool share of the study's tests with that minimum
    (χ² on pooled tests). None of them when a side has no study tests."""
    if a.study_tests.empty or b.study_tests.empty:
        return []
    sides = [tool_motion(s.study_tests, min_motion).iloc[0].to_dict() for s in (a, b)]
    minimum = _minimum_text(min_motion)
    recorded = not any(math.isnan(s["small"]) for s in sides)
    small = np.array([[s["small"], s["tool"] - s["small"]] for s in sides]) if recorded else None
    kept = (
        np.array([[s["tool"] - s["small"], s["tests"] - s["tool"] + s["small"]] for s in sides])
        if recorded
        else None
    )
    test = "χ² (pooled tests)"
    return [
        [
            f"Study's tool uses that moved the stick's x less than {minimum}",
            *[_small_text(s) for s in sides],
            test,
            p_value(chi_square(small)[1]) if small is not None else "n/a",
        ],
        [
            f"Study's tests: tool share, its rule / with at least {minimum}",
            *[
                f"{pct(s['tool_share'], 1)} / {pct(s['tool_share_min_motion'], 1)} (n={s['tests']})"
                for s in sides
            ],
            f"{test}, with at least {minimum}",
            p_value(chi_square(kept)[1]) if kept is not None else "n/a",
        ],
    ]
