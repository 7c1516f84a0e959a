"""A page's tests computed again from its per-trial data alone, with scipy, as a reader would: a
comparison page's (comparison-trials.csv: tests/report/test_comparison_data.py, test_report.py,
test_comparison_doc_data.py) and the contact ladder's (ladder-trials.csv: test_ladder.py,
test_ladder_doc_data.py)."""

from __future__ import annotations

import math
import shlex
import warnings
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from scipy import stats

from experiments.analysis.trial_tests import holm
from experiments.report.pages import survive
from experiments.report.trial_data import read_trial_data


def _approx(x: float):
    return pytest.approx(x, rel=1e-9, abs=1e-15)


def _column(trials: pd.DataFrame, test: dict) -> str:
    """A test's column: `measure:part` for a part of several, else the measure's one value."""
    named = f"{test['measure']}:{test['part']}"
    return named if named in trials.columns else test["measure"]


def _by_seed(trials: pd.DataFrame, group: str, column: str) -> pd.Series:
    return trials[trials["group"] == group].set_index("seed")[column].astype(float)


def recomputed(trials: pd.DataFrame, test: dict) -> dict[str, float]:
    """One test of summary.json's `trial_tests` (its measure, part, groups and pairing) from the
    per-trial table: the difference (or mean), the t's p and the nonparametric p; NaN where
    there is no test (fewer than two values a side, or no variance)."""
    column, groups = _column(trials, test), list(test["n"])
    if len(groups) == 1:  # a group's values against 0
        x = _by_seed(trials, groups[0], column)
        x = x[np.isfinite(x)].to_numpy()
        if len(x) < 2 or np.all(x == x[0]):
            return {"difference": x.mean(), "p": math.nan, "rank_p": math.nan}
        rank = stats.wilcoxon(x, zero_method="pratt").pvalue
        return {"difference": x.mean(), "p": stats.ttest_1samp(x, 0).pvalue, "rank_p": rank}
    a, b = (_by_seed(trials, g, column) for g in groups)
    if test["paired"]:
        d = (a - b).dropna()
        d = d[np.isfinite(d)].to_numpy()
        if len(d) < 2 or np.all(d == d[0]):
            return {"difference": d.mean(), "p": math.nan, "rank_p": math.nan}
        rank = stats.wilcoxon(d, zero_method="pratt").pvalue
        return {"difference": d.mean(), "p": stats.ttest_1samp(d, 0).pvalue, "rank_p": rank}
    x, y = (s[np.isfinite(s)].to_numpy() for s in (a, b))
    difference = x.mean() - y.mean()
    if len(x) < 2 or len(y) < 2 or (np.var(x) == 0 and np.var(y) == 0):
        return {"difference": difference, "p": math.nan, "rank_p": math.nan}
    with warnings.catch_warnings():
        # One side constant (every test held the stick): scipy warns of precision loss, as the
        # page's Welch test does (experiments/analysis/stats.py welch); the p is still its.
        warnings.simplefilter("ignore", RuntimeWarning)
        p = stats.ttest_ind(x, y, equal_var=False).pvalue
    rank = stats.mannwhitneyu(x, y, alternative="two-sided").pvalue
    return {"difference": difference, "p": p, "rank_p": rank}


def check_tests_again(trials: pd.DataFrame, tests: list[dict]) -> None:
    """Every test of the page (summary.json's `trial_tests`' tests) and both Holm adjustments
    over them, computed again from the per-trial table, are the page's."""
    again = [recomputed(trials, t) for t in tests]
    for kind, holm_kind in (("p", "holm_p"), ("rank_p", "rank_holm_p")):
        adjusted = holm([a[kind] for a in again])
        for test, a, h in zip(tests, again, adjusted, strict=True):
            for value, expected in ((test[kind], a[kind]), (test[holm_kind], h)):
                if math.isnan(expected):
                    assert value is None or math.isnan(value), (test, kind)
                else:
                    assert value == _approx(expected), (test, kind)
    for test, a in zip(tests, again, strict=True):
        if test["difference"] is not None:
            assert test["difference"] == _approx(a["difference"]), test


def check_trials_file(out: Path, page: str, tests: list[dict]) -> pd.DataFrame:
    """comparison-trials.csv beside a comparison page written into `out` (`page` its HTML,
    `tests` its summary.json's tests): linked from the page, who learned and evaluated each
    trial recorded, and every test of the page computed again from it. Returns the table."""
    assert 'href="comparison-trials.csv"' in page
    trials = read_trial_data(out / "comparison-trials.csv")
    assert trials["computed_commit"].str.fullmatch(r"[0-9a-f]{7}(\+dirty)?").all()
    assert trials["computed_on"].str.contains("from iteration 0").all()
    assert trials["evaluated_on"].ne("not recorded").all()
    check_tests_again(trials, tests)
    return trials


def ladder_case(trials: pd.DataFrame, case: dict, seeds: set[int]) -> dict[str, float]:
    """One test of the ladder's family (`case`: key, from, to, part, world) from its per-trial
    table (a row per rung, world tested in and seed): B minus A on the given seeds, the step in
    the rungs' own worlds or a part of its split in `world`, pairs with an empty cell left out.
    Its mean, 95% t interval, t p and signed-rank p (NaN where every pair is equal), pairs."""

    def values(rung: str, tested: str) -> pd.Series:
        mine = trials[(trials["rung"] == rung) & (trials["tested"] == tested)]
        return mine.set_index("seed")[case["key"]].loc[lambda v: v.index.isin(seeds)]

    a, b, world = case["from"], case["to"], case.get("world")
    if case["part"] == "step":
        diff = values(b, "own") - values(a, "own")
    elif case["part"] == "both_in_world":
        diff = values(b, world) - values(a, world)
    else:
        diff = (values(b, "own") - values(b, world)) - (values(a, "own") - values(a, world))
    return _paired_against_zero(diff)


def _paired_against_zero(diff: pd.Series) -> dict[str, float]:
    """Per-seed differences (an empty or infinite one left out) against zero: mean, 95% t
    interval, t p, signed-rank p (NaN where every pair is equal), pairs."""
    d = diff.dropna().to_numpy()
    d = d[np.isfinite(d)]
    if len(d) < 2 or np.all(d == d[0]):
        mean = d.mean() if len(d) else math.nan
        return {
            "mean": mean,
            "low": mean,
            "high": mean,
            "p": math.nan,
            "p_rank": math.nan,
            "n": len(d),
        }
    half = stats.t.ppf(0.975, len(d) - 1) * stats.sem(d)
    return {
        "mean": d.mean(),
        "low": d.mean() - half,
        "high": d.mean() + half,
        "p": stats.ttest_1samp(d, 0.0).pvalue,
        "p_rank": stats.wilcoxon(d, zero_method="pratt").pvalue,
        "n": len(d),
    }


def check_factorial_page(page: str, trials: pd.DataFrame, measures: list) -> None:
    """A factorial page (`playroom factorial`'s factorial.md) against its per-trial data
    (factorial-trials.csv) alone: the cells named by its command, each contrast of each measure
    (`measures`: the ladder's headline) per seed on the seeds all four cells hold, computed with
    scipy, Holm over the family for each kind of p, and every cell of its table written from
    those numbers; the family's counts as the page states them."""
    from experiments.analysis.trial_tests import survives
    from experiments.report.factorial import CONTRASTS
    from experiments.report.paired_text import cell_text, level_text

    command = page.split("Written by `", 1)[1].split("`", 1)[0]
    words = shlex.split(command)
    cells = [w.split("=")[0] for w in words[: words.index("--factors")] if "=" in w]
    own = trials[trials["tested"] == "own"]
    seeds = set.intersection(*(set(own.loc[own["rung"] == c, "seed"]) for c in cells))
    own = own[own["seed"].isin(seeds)]
    rows = []
    for h in measures:
        table = own.pivot(index="seed", columns="rung", values=h.key)
        for name, w in CONTRASTS.items():
            weights = {c: x for c, x in zip(cells, w, strict=True) if x}
            rows.append(
                {"key": h.key, "contrast": name}
                | _paired_against_zero(sum(table[c] * x for c, x in weights.items()))
            )
    tests = pd.DataFrame(rows)
    tests["p_holm"] = holm(list(tests["p"]))
    tests["p_rank_holm"] = holm(list(tests["p_rank"]))
    lines = {line.split(" | ")[0][2:]: line for line in page.splitlines() if line.startswith("| ")}
    for h in measures:
        cells_text = [c.strip() for c in lines[h.label].strip("|").split(" | ")][1:]
        mine = tests[tests["key"] == h.key].to_dict("records")
        means = [level_text(h.measure.kind, own.loc[own["rung"] == c, h.key].mean()) for c in cells]
        assert cells_text == means + [cell_text(h.measure.kind, r) for r in mine], h.label
    made = tests[np.isfinite(tests["p"])]
    t = int(sum(survives(p) for p in made["p_holm"]))
    rank = int(sum(survives(p) for p in made["p_rank_holm"]))
    assert f"One family of {len(tests)} tests" in page and f"; {len(made)} could be made." in page
    assert f"{survive(t)} with the paired t, {rank} with the signed-rank test." in page


def study_headline() -> list:
    """The ladder's and factorial's headline measures (labels and kinds) for the study preset's
    world and voice, as the published pages name them."""
    from experiments.analysis.geometry import Geometry
    from experiments.report import ladder
    from sim.config import world_preset
    from sim.vocal.config import VoiceConfig

    world, voice = world_preset("study"), VoiceConfig()
    hand = float(sum(world.segment_lengths))
    geometry = Geometry(hand, hand + world.stick_length, voice.recognition_distance, 0)
    return ladder.headline(geometry)


def page_table(text: str, head: str) -> list[list[str]]:
    """The cells of each row of the markdown table whose header line starts with `head`."""
    rows = []
    for line in text[text.index(head) :].splitlines()[2:]:
        if not line.startswith("|"):
            break
        rows.append([c.strip() for c in line.strip("|").split(" | ")])
    return rows
