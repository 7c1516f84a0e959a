"""The factorial pages in docs/ computed again from the per-trial data each publishes
(docs/data/contact-factorial-*-trials.csv) alone, with scipy (trial_recompute.py
`check_factorial_page`): every contrast's mean, interval, t and signed-rank p, the Holm stars
and counts over the page's family, and each cell's mean. A cell edited by hand, or a CSV from
other trials, fails here."""

from __future__ import annotations

from pathlib import Path

import pytest
from trial_recompute import check_factorial_page, study_headline

from experiments.report.trial_data import read_trial_data

DOCS = Path(__file__).resolve().parents[2] / "docs"
# Each published factorial (`make contact-factorial`): its page and the per-trial data beside it.
DESIGNS = ("held-pose-pushing", "catch-servo", "catch-distance")


@pytest.mark.parametrize("design", DESIGNS)
def test_every_cell_of_a_published_factorial_is_computed_again(design):
    page = (DOCS / f"contact-factorial-{design}.md").read_text()
    trials = read_trial_data(DOCS / "data" / f"contact-factorial-{design}-trials.csv")
    assert trials["computed_commit"].str.fullmatch(r"[0-9a-f]{7}").all()
    check_factorial_page(page, trials, study_headline())
