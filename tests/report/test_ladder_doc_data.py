"""docs/contact-ladder.md computed again from the per-trial data it publishes
(docs/data/contact-ladder-trials.csv) alone: every test of the page's declared family
(experiments/report/ladder.py `family`, from the rungs its command names) with scipy
(trial_recompute.py), Holm's correction over them for each kind of p, and every cell of the
page's two tables of tests written from those numbers. A cell edited by hand, a star that does
not follow from the family, or a CSV from other trials fails here."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from trial_recompute import ladder_case, page_table, study_headline

from experiments.analysis.trial_tests import holm, survives
from experiments.report import ladder
from experiments.report.pages import survive
from experiments.report.paired_text import cell_text, level_text
from experiments.report.trial_data import read_trial_data

DOCS = Path(__file__).resolve().parents[2] / "docs"
# Each published ladder page (`playroom ladder`) and the per-trial data beside it.
PAGES = {
    "contact-ladder.md": "contact-ladder-trials.csv",
    "contact-unbundled.md": "contact-unbundled-trials.csv",
    "held-pose-returns.md": "held-pose-returns-trials.csv",
}


def _rungs(text: str) -> tuple[list[str], list[str]]:
    """The ladder's rungs and those beside it, in order, from the command the page names."""
    words = re.search(r"Written by `(playroom ladder [^`]*)`", text).group(1).split()
    cut = words.index("--beside") if "--beside" in words else len(words)
    return [w.split("=")[0] for w in words[:cut] if "=" in w], [
        w.split("=")[0] for w in words[cut:] if "=" in w
    ]


@pytest.fixture(scope="module", params=PAGES)
def page(request):
    text = (DOCS / request.param).read_text()
    trials = read_trial_data(DOCS / "data" / PAGES[request.param])
    order, beside = _rungs(text)
    measures = study_headline()
    own = trials[trials["tested"] == ladder.OWN]
    common = set.intersection(*(set(own.loc[own["rung"] == r, "seed"]) for r in order))
    ends = [set(own.loc[own["rung"] == r, "seed"]) for r in (order[0], order[-1])]
    family = ladder.family(order, beside, measures, len(ends[0] & ends[1]) > len(common))
    every = set(own["seed"])
    tests = []
    for case in family.to_dict("records"):
        seeds = common if case["kind"] in (ladder.STEP, ladder.WHOLE) else every
        tests.append({**case, **ladder_case(trials, case, seeds)})
    tests = pd.DataFrame(tests)
    tests["p_holm"] = holm(list(tests["p"]))
    tests["p_rank_holm"] = holm(list(tests["p_rank"]))
    return text, trials, order, beside, measures, common, tests


def test_the_published_trials_hold_every_rung_in_every_world(page):
    _, trials, order, beside, _, common, _ = page
    assert set(trials["rung"]) == {*order, *beside}
    assert set(trials["tested"]) == {ladder.OWN, *ladder.WORLDS}
    assert sorted(common) == list(range(32))  # the rungs' seeds 0-31
    assert trials["computed_commit"].str.fullmatch(r"[0-9a-f]{7}").all()
    assert trials["evaluated_on"].ne("not recorded").all()


def test_every_step_cell_is_computed_again_from_the_published_trials(page):
    text, trials, order, beside, measures, common, tests = page
    rows = {r[0]: r for r in page_table(text, f"| measure | {order[0]} (mean) |")}
    steps = tests[tests["part"] == "step"]
    own = trials[(trials["tested"] == ladder.OWN) & trials["seed"].isin(common)]
    for h in measures:
        cells = rows[h.label]
        kind = h.measure.kind
        first, last = (own.loc[own["rung"] == r, h.key].mean() for r in (order[0], order[-1]))
        mine = steps[steps["key"] == h.key].to_dict("records")
        expected = [level_text(kind, first), *(cell_text(kind, r) for r in mine)]
        expected.insert(len(order), level_text(kind, last))
        assert cells[1:] == expected, h.label


def test_every_split_cell_is_computed_again_from_the_published_trials(page):
    text, _, _, _, _, _, tests = page
    head = "| step | part | all | ring1 | ring2 | ring3 |"
    rows = {(r[0], r[1].split(" (")[0]): r[2:] for r in page_table(text, head)}
    splits = tests[tests["part"] != "step"]
    assert len(rows) == len(splits) // len(ladder.COMPETENCE)
    for (a, b, kind, world, part), cases in splits.groupby(
        ["from", "to", "kind", "world", "part"], sort=False
    ):
        step = f"{a} -> {b}" + {"whole": " (whole)"}.get(kind, "")
        name = "both tested in the " if part == "both_in_world" else "own worlds against the "
        cells = rows[(step, f"{name}{world} world")]
        by_key = cases.set_index("key")
        assert cells == [cell_text("share", by_key.loc[k]) for k in ladder.COMPETENCE], step


def test_the_holm_counts_follow_from_the_recomputed_family(page):
    text, _, _, _, _, _, tests = page
    made = tests[np.isfinite(tests["p"])]
    t = int(sum(survives(p) for p in made["p_holm"]))
    rank = int(sum(survives(p) for p in made["p_rank_holm"]))
    assert f"One family of {len(tests)} tests" in text
    assert f"{len(made)} of them could be made" in text
    assert f"{survive(t)} with the paired t, {rank} with the Wilcoxon" in text
