"""Pages a reader understands without the paper: intervals that would
mislead are flagged, the rings are named in metres. The pages themselves are checked in
tests/report/test_report.py (page_checks.check_explained)."""

from __future__ import annotations

import pandas as pd

from experiments.analysis.geometry import Geometry
from experiments.report import paper
from experiments.report.ablation_tests import AblationNumbers
from experiments.report.ablations import COMPETENCE, STUDY_REGIONS, AblationRow, ablation_figure
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


def _bands(metrics: list[str]) -> pd.DataFrame:
    """Curves that barely move near the top of their range: 97.5-100% within reach."""
    rows = []
    for metric in metrics:
        for i, value in enumerate((1.0, 0.975, 0.99)):
            rows.append(("kinematic", metric, 100 * (i + 1), value, value - 0.01, value))
    return pd.DataFrame(rows, columns=["group", "metric", "iteration", "mean", "low", "high"])


def test_figure_axes_start_at_zero_and_carry_units():
    from experiments.report.figures import development, stick_in_play

    stick = stick_in_play(_bands(["stick_in_reach", "stick_grasp", "tool_use"]), ["kinematic"], 50)
    reach, grasps, catches = stick.axes
    assert reach.get_ylim() == (0.0, 100.0) and "%" in reach.get_ylabel()
    assert grasps.get_ylim()[0] == 0 and catches.get_ylim()[0] == 0
    metrics = ["tool_use", "word_recognised", "best_distance_names", "best_distance_distractors"]
    curves = development(_bands(metrics), ["kinematic"], 50, 0.4)
    tool, words, distance = curves.axes
    assert tool.get_ylim()[0] == 0 and words.get_ylim()[0] == 0
    assert "(log2 Hz)" in distance.get_ylabel()
    for ax in (*stick.axes, *curves.axes):
        assert "iteration" in ax.get_xlabel()


def _ablation_row(label: str, difference: float) -> AblationRow:
    shares = {r: {"hand": 0.5, "tool": 0.2, "vocal": 0.3} for r in STUDY_REGIONS}
    competence = AblationNumbers(0.3, 4, difference, difference - 0.05, difference + 0.05, 0.2, 4)
    return AblationRow(
        label, "batch", "kinematic", 4, 0.4, shares, {COMPETENCE: competence}, 0.25, 0.31, 0.01
    )


def test_the_ablation_figure_is_titled_in_words_with_the_papers_values():
    rows = [
        _ablation_row("baseline (study)", float("nan")),
        _ablation_row("learner.exploration_sigma: 0.05 -> 0.1; world.stick_return: none", 0.02),
    ]
    fig = ablation_figure(rows)
    assert "Ablations" in fig.get_suptitle()
    left, middle, right = fig.axes[:3]
    ticks = [t.get_text().replace("\n", " ") for t in left.get_yticklabels()]
    assert ticks[1] == "exploration sigma (learner): 0.05 → 0.1; stick return (world): none"
    assert "_" not in " ".join(ticks)
    legends = [t.get_text() for ax in (middle, right) for t in ax.get_legend().get_texts()]
    published = paper.published()
    assert f"paper, names: {published['median_names'].value:g}" in legends
    assert f"paper, distractors: {published['median_distractors'].value:g}" in legends
    assert "paper, centre: 15%–20%" in legends and "between limits" in legends
    assert not any("_" in text for text in legends)
