"""Pages a reader understands without the paper (issue 21, point 7): intervals that would
mislead are flagged, the rings are named in metres. The pages themselves are checked in
tests/report/test_report.py (page_checks.check_explained)."""

from __future__ import annotations

import pandas as pd

from experiments.analysis.geometry import Geometry
from experiments.report.intro import rings_text
from experiments.report.pages import ci_text


def _row(mean: float, low: float, high: float, n: int) -> pd.Series:
    return pd.Series({"mean": mean, "low": low, "high": high, "n": n}, dtype=object)


def test_a_zero_width_interval_says_why():
    equal = ci_text(_row(-0.008, -0.008, -0.008, 2))
    assert equal == "-0.8% [95% CI -0.8%, -0.8%] (n=2; all trials equal; fewer than 5 trials)"
    narrow = ci_text(_row(0.4601, 0.4600, 0.4602, 12))
    assert narrow == "46.0% [95% CI 46.0%, 46.0%] (n=12; interval under 0.1% wide)"


def test_tiny_samples_are_flagged_and_enough_trials_are_not():
    assert ci_text(_row(0.4, 0.2, 0.6, 4)).endswith("(n=4; fewer than 5 trials)")
    assert ci_text(_row(0.4, 0.3, 0.5, 5)) == "40.0% [95% CI 30.0%, 50.0%] (n=5)"


def test_rings_are_said_in_metres_with_who_reaches_them():
    study = {"world": {"toy_rings": [[0.0, 0.5], [0.5, 0.75], [0.75, 1.0]]}}
    geometry = Geometry(hand_limit=0.5, stick_limit=0.75, threshold=0.4, bootstrap=100)
    assert rings_text(study, geometry) == [
        "ring 1: 0–0.5 m (within the hand's reach)",
        "ring 2: 0.5–0.75 m (beyond the hand, within the stick's reach)",
        "ring 3: 0.75–1 m (beyond both: only the caregiver can bring it)",
    ]
    # Rings of another layout are given in metres without a meaning they do not have.
    other = {"world": {"toy_rings": [[0.0, 0.3], [0.3, 1.0]]}}
    assert rings_text(other, geometry) == ["ring 1: 0–0.3 m", "ring 2: 0.3–1 m"]
