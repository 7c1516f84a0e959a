"""docs/comparison.md's table of differences computed again from the per-trial data it
publishes (docs/data/comparison-diva-trials.csv) alone, as a reader would with scipy
(trial_recompute.py, which recomputes the generated pages the same way): each quoted row's two
means, its paired t's p and the signed-rank p beside it. A row edited by hand, or a CSV from
other trials, fails here."""

from __future__ import annotations

import re
from pathlib import Path

import pandas as pd
import pytest
from trial_recompute import page_table, recomputed

from experiments.report.pages import p_value
from experiments.report.trial_data import read_trial_data

DOCS = Path(__file__).resolve().parents[2] / "docs"
GROUPS = ("kinematic", "physical")
# Quoted row -> its column in the CSV, and the factor its means are printed with.
ROWS = {
    "Normalised competence, all rings": ("competence_all", 100),
    "Normalised competence, ring 1": ("competence_ring1", 100),
    "Normalised competence, ring 2": ("competence_ring2", 100),
    "Normalised competence, ring 3": ("competence_ring3", 100),
    "Words imitated within 0.4 (each trial's share of its words)": ("words_within", 100),
    "Stick grasps per 1000 arm movements": ("stick_grasps_per_1000_arm", 1),
    "Toys caught with the stick per 1000 arm movements": ("toy_catches_per_1000_arm", 1),
}


def _table_rows(text: str) -> dict[str, list[str]]:
    """The cells of the first table of differences, by measure."""
    head = "| measure (mean over trials [95% t interval]) | kinematic | physical |"
    return {row[0]: row for row in page_table(text, head)}


@pytest.fixture(scope="module")
def published() -> tuple[pd.DataFrame, dict[str, list[str]]]:
    trials = read_trial_data(DOCS / "data" / "comparison-diva-trials.csv")
    return trials, _table_rows((DOCS / "comparison.md").read_text())


def test_the_published_trials_are_the_profiles_own(published):
    trials, _ = published
    assert sorted(trials["grasp"].unique()) == ["kinematic", "physical"]
    for _, group in trials.groupby("grasp"):
        assert sorted(group["seed"]) == list(range(64))  # the comparison-diva profile's seeds
    assert trials["computed_commit"].nunique() == 1  # every trial learned by one commit


@pytest.mark.parametrize("measure", ROWS)
def test_a_quoted_row_is_computed_again_from_the_published_trials(published, measure):
    trials, rows = published
    column, factor = ROWS[measure]
    by_seed = {g: t.set_index("seed")[column].astype(float) for g, t in trials.groupby("group")}
    cells = rows[measure]
    for group, cell in zip(GROUPS, cells[1:3], strict=True):
        mean = float(re.match(r"(-?[0-9.]+)", cell).group(1))
        assert mean == pytest.approx(by_seed[group].mean() * factor, abs=0.051), (group, cell)
        assert f"(n={len(by_seed[group])} trials" in cell
    # The page's test of the row: the sides paired by seed, kinematic minus physical.
    again = recomputed(trials, {"measure": column, "part": "", "n": GROUPS, "paired": True})
    assert cells[4] == p_value(again["p"])
    assert cells[6] == f"Wilcoxon signed-rank over seeds: {p_value(again['rank_p'])}"
