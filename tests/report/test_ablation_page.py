"""The ablation table's tests and its per-trial data (experiments/report/ablation_page.py,
ablation_tests.py, ablation_data.py) on hand-made batches whose answers are known: a
signed-rank p beside every t, Holm over one declared family for each kind of p, the cells whose
star differs between the two named, and every number of the table computed again from
ablations-trials.csv alone."""

from __future__ import annotations

import dataclasses
import io
import math

import numpy as np
import pandas as pd
import pytest
from scipy import stats
from trial_batches import batch

from experiments.analysis.trial_tests import holm
from experiments.measure.for_reports import room_measures
from experiments.report.ablations import ablation_files
from experiments.report.trial_data import read_trial_data
from experiments.run.settings import TrialSettings
from experiments.run.trial_config import full_config

# Five seeds: the signed-rank test's smallest two-sided p is 2 / 2^5 = 0.0625, so it can star
# nothing, while the t stars a difference that every seed shows.
SEEDS = list(range(5))
COMPETENCE = np.array([0.10, 0.25, 0.18, 0.30, 0.05])
MEASURES = ("competence_all", "words_within", "names_vs_distractors")
SECTION = "## Where the t and the signed-rank test disagree on a star"


def _words(gap: float, jitter: float) -> tuple[list[float], list[float]]:
    names = [0.2 + jitter, 0.35, 0.5 - jitter]
    return names, [d + gap for d in names]


def _batch(name: str, competence: np.ndarray, gaps: list[float], **overrides):
    """One group of hand-made trials under `name`, with the config of a kinematic trial whose
    settings `overrides` changes (the row's label)."""
    words = [_words(g, 0.01 * k) for k, g in enumerate(gaps)]
    results = batch("kinematic", SEEDS, competence=competence, words=words)
    config = full_config(TrialSettings(grasp="kinematic", overrides=overrides))
    return dataclasses.replace(
        results, batch_dir=results.batch_dir.with_name(name), configs={"kinematic": config}
    )


@pytest.fixture(scope="module")
def files() -> dict[str, bytes]:
    """A baseline, an ablation that raises competence on every seed (the t stars it, the
    signed-rank test cannot) and one that changes nothing but the noise."""
    gaps = [0.1, 0.05, 0.12, 0.08, 0.02]
    noise = np.array([0.01, -0.02, 0.015, 0.0, -0.01])
    baseline = _batch("baseline", COMPETENCE, gaps)
    raised = _batch(
        "sigma", COMPETENCE + 0.1 + 0.01 * noise, gaps, learner={"exploration_sigma": 0.05}
    )
    other = _batch("wider", COMPETENCE + noise, gaps[::-1], learner={"exploration_sigma": 0.2})
    return ablation_files(baseline, [raised, other], room_measures(20))


def test_every_t_has_a_signed_rank_p_and_each_disagreeing_star_is_named(files):
    page = files["ablations.md"].decode()
    table = page.split("\n\n")[0]
    # Every p of a test in the table's cells (not its pooled last column) has its rank p.
    cells = [c for line in table.splitlines()[2:] for c in line.split(" | ")[6:-2]]
    assert (
        sum(c.count("p = ") - c.count("rank p = ") for c in cells)
        == sum(c.count("rank p = ") for c in cells)
        > 0
    )
    # 3 measures x 2 ablations, and the gap against 0 in each of the 3 rows.
    assert "One family of 9 tests, fixed by the table's rows and measures" in page
    numbers = pd.read_csv(io.BytesIO(files["ablations.csv"]))
    raised = numbers.iloc[1]
    assert raised["competence_all_holm_p"] <= 0.05 < raised["competence_all_rank_holm_p"]
    assert raised["competence_all_rank_p"] == pytest.approx(2 / 2**5)
    section = page.split(SECTION)[1]
    assert section.count("starred by the t only") >= 1
    assert (
        "- learner.exploration_sigma: 0.1 -> 0.05, Normalised competence, all rings "
        "(difference from the baseline): starred by the t only" in section
    )
    assert "0.1 -> 0.2" not in section and "0.1 -> 0.2" in table


def _holm_columns(numbers: pd.DataFrame) -> dict[tuple[int, str], float]:
    """Holm's adjustment of each kind of p over the family, computed again from the table's
    raw ps (the family: each ablation's differences, every row's gap against 0)."""
    out = {}
    for kind in ("", "rank_"):
        cases = []
        for i, row in numbers.iterrows():
            for m in MEASURES:
                if not row["baseline"]:
                    cases.append((i, f"{m}_{kind}p", f"{m}_{kind}holm_p"))
                if m == "names_vs_distractors":
                    cases.append((i, f"{m}_within_{kind}p", f"{m}_within_{kind}holm_p"))
        adjusted = holm([numbers.loc[i, p] for i, p, _ in cases])
        out |= {(i, column): a for (i, _, column), a in zip(cases, adjusted, strict=True)}
    return out


def test_every_number_of_the_table_is_computed_again_from_its_per_trial_data_alone(files):
    """ablations-trials.csv holds all a reader needs: each row's means, its paired differences
    from the baseline with their interval, t and signed-rank p, the gap against 0 with both
    ps, and their Holm adjustments, computed from it with scipy are ablations.csv's."""
    trials = read_trial_data(io.BytesIO(files["ablations-trials.csv"]))
    numbers = pd.read_csv(io.BytesIO(files["ablations.csv"]))
    assert {"row", "baseline", "batch", "group", "seed", "trial", "grasp"} <= set(trials)
    assert {"computed_on", "computed_commit", "evaluated_on", "evaluated_commit"} <= set(trials)
    assert list(trials["row"].drop_duplicates()) == list(numbers["label"])
    numbers["baseline"] = [bool(b) for b in trials.groupby("row", sort=False)["baseline"].first()]
    base = trials[trials["baseline"]].set_index("seed")
    for _, row in numbers.iterrows():
        mine = trials[trials["row"] == row["label"]].set_index("seed")
        for m in MEASURES:
            assert row[f"{m}_mean"] == pytest.approx(mine[m].mean(), rel=1e-12)
            if m == "names_vs_distractors":
                values = mine[m].to_numpy()
                assert row[f"{m}_within_p"] == pytest.approx(stats.ttest_1samp(values, 0).pvalue)
                assert row[f"{m}_within_rank_p"] == pytest.approx(stats.wilcoxon(values).pvalue)
            if row["baseline"]:
                assert math.isnan(row[f"{m}_difference"])
                continue
            d = (mine[m] - base[m]).dropna().to_numpy()
            assert row[f"{m}_difference"] == pytest.approx(d.mean(), abs=1e-15)
            assert row[f"{m}_n_pairs"] == len(d) == len(SEEDS)
            if np.all(d == d[0]):  # every pair equal: no test
                assert math.isnan(row[f"{m}_p"]) and math.isnan(row[f"{m}_rank_p"])
                continue
            half = stats.t.ppf(0.975, len(d) - 1) * stats.sem(d)
            assert row[f"{m}_low"] == pytest.approx(d.mean() - half)
            assert row[f"{m}_high"] == pytest.approx(d.mean() + half)
            assert row[f"{m}_p"] == pytest.approx(stats.ttest_1samp(d, 0).pvalue)
            expected = stats.wilcoxon(d, zero_method="pratt").pvalue
            assert row[f"{m}_rank_p"] == pytest.approx(expected)
    for (i, column), adjusted in _holm_columns(numbers).items():
        assert numbers.loc[i, column] == pytest.approx(adjusted, nan_ok=True), column
