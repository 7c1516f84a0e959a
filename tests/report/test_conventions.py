"""One p-value convention everywhere (the study's: the one-sided Mann-Whitney p doubled), and
every paper number shown with the number of runs it came from."""

from __future__ import annotations

import dataclasses
import html
import json
import re
from importlib import resources

import numpy as np
import pandas as pd
import pytest
from scipy import stats

from experiments.analysis.stats import mann_whitney, vocal_summary
from experiments.measure.for_reports import room_measures
from experiments.report import paper
from experiments.report.batch_report import write_report


def test_the_p_is_the_one_sided_p_doubled_capped_at_1():
    names = np.array([0.10, 0.12, 0.15, 0.20, 0.22, 0.25, 0.31, np.inf])
    distractors = np.array([0.18, 0.24, 0.28, 0.30, 0.35, 0.40, 0.45, 0.50, np.inf])
    one_sided = stats.mannwhitneyu(names, distractors, alternative="less")
    u, p = mann_whitney(names, distractors)
    assert u == one_sided.statistic
    assert p == pytest.approx(2 * one_sided.pvalue) and p < 0.1  # not capped
    # The same words the other way round: the data lean the other way, the same p.
    assert mann_whitney(distractors, names)[1] == pytest.approx(p)
    # No difference: the doubled one-sided p passes 1 and is capped there.
    same = np.array([0.2, 0.3, 0.4])
    assert 2 * stats.mannwhitneyu(same, same, alternative="less").pvalue > 1
    assert mann_whitney(same, same)[1] == 1.0
    # The report's vocal numbers carry that p.
    vocal = {
        "is_name": [True] * len(names) + [False] * len(distractors),
        "best_distance": [*names, *distractors],
    }
    assert vocal_summary(pd.DataFrame(vocal), 0.4)["p"] == pytest.approx(p)


def _cells(page: str, first_cell: str) -> list[str]:
    for row in re.findall(r"<tr>(.*?)</tr>", page, flags=re.S):
        cells = [html.unescape(c) for c in re.findall(r"<td>(.*?)</td>", row, flags=re.S)]
        if cells and cells[0].startswith(first_cell):
            return cells
    raise AssertionError(f"no row {first_cell!r}")


def test_every_paper_number_says_how_many_runs_it_came_from(batches, tmp_path, monkeypatch):
    numbers = paper.published()
    # The notebooks computed the map and Fig. 4 from 100 runs; the vocal numbers are the text's.
    assert {n.runs for k, n in numbers.items() if k.startswith(("competence", "strategy"))} == {100}
    assert {numbers[k].runs for k in ("median_names", "mann_whitney_p", "runs")} == {500}
    edited = dataclasses.replace(numbers["strategy_distance_1"], runs=7)
    monkeypatch.setattr(paper, "published", lambda: {**numbers, "strategy_distance_1": edited})
    page = write_report(batches["kinematic"], tmp_path / "r", measures=room_measures(20))
    text = page.read_text()
    header = re.search(r"<thead><tr>(.*?)</tr></thead>", text.split("Paper vs this batch")[1])
    assert header is not None and "<th>paper</th>" in header.group(1)
    shown = {
        "Normalised competence, all rings": "competence_all",
        "Strategy hand / tool / vocal, centre region": "strategy_centre",
        "Strategy hand / tool / vocal, at distance 1": "strategy_distance_1",
        "Words imitated within": "words_below_threshold",
        "Median best distance, distractors": "median_distractors",
        "Mann-Whitney U, names vs distractors": "mann_whitney_p",
    }
    for label, key in shown.items():
        runs = 7 if key == "strategy_distance_1" else numbers[key].runs
        assert _cells(text, label)[1] == f"{numbers[key].text} (from {runs} runs)"
    assert "two-sided p: the one-sided p doubled" in _cells(text, "Mann-Whitney U")[0]
    assert _cells(text, "Mann-Whitney U")[1].startswith("two-sided p < 1e-72")


def test_a_paper_number_without_its_run_count_is_refused(tmp_path):
    raw = json.loads(
        resources.files("experiments.report").joinpath("data", "paper.json").read_text()
    )
    del raw["numbers"]["competence_all"]["runs"]
    path = tmp_path / "paper.json"
    path.write_text(json.dumps(raw))
    with pytest.raises(ValueError, match="competence_all lacks runs"):
        paper.load(path)
    raw["numbers"]["competence_all"]["runs"] = "100 runs"
    path.write_text(json.dumps(raw))
    with pytest.raises(ValueError, match="competence_all runs must be a whole number"):
        paper.load(path)


@pytest.mark.parametrize("fraction", [0.46, -0.008, 0.0, 1.0, float("nan")])
def test_the_cli_prints_competence_as_the_pages_do(fraction):
    from experiments.cli.args import percent
    from experiments.report.pages import pct

    assert percent(fraction) == pct(fraction, 1)
