"""Checks of summary.json and summary.csv beside a report or comparison page: the numbers the
page shows, read from the files and printed as the page prints them, are the page's
(tests/report/test_report.py calls them on the pages it writes)."""

from __future__ import annotations

import html
import json
import re

import pandas as pd
import pytest

from experiments.batch_files import SUMMARY_CSV_FILE, SUMMARY_JSON_FILE
from experiments.trial_dir import provenance


def _rows(page: str) -> list[list[str]]:
    """Every table row of a page, its cells as unescaped text."""
    return [
        [html.unescape(c) for c in re.findall(r"<t[dh]>(.*?)</t[dh]>", row, flags=re.S)]
        for row in re.findall(r"<tr>(.*?)</tr>", page, flags=re.S)
    ]


def _row(page: str, first_cell: str, ending: str = "") -> list[str]:
    """The first row whose first cell starts with `first_cell` (and ends with `ending`)."""
    found = [r for r in _rows(page) if r and r[0].startswith(first_cell) and r[0].endswith(ending)]
    assert found, f"no row {first_cell!r}"
    return found[0]


# The page's ways of printing a number, from the summary's values (null: "n/a").
def _pct(x, digits: int = 0) -> str:
    return "n/a" if x is None else f"{100 * x:.{digits}f}%"


def _num(x, digits: int = 2) -> str:
    return "n/a" if x is None else f"{x:.{digits}f}"


def _competence(c: dict) -> str:
    if c["low"] is None:
        return f"{_pct(c['mean'], 1)} (n={c['n']}, no interval)"
    notes = ""
    if _pct(c["low"], 1) == _pct(c["high"], 1):  # a zero-width interval is flagged
        notes += "; all trials equal" if c["low"] == c["high"] else "; interval under 0.1% wide"
    if c["n"] < 5:  # and so is a tiny sample
        notes += "; fewer than 5 trials"
    interval = f"[95% CI {_pct(c['low'], 1)}, {_pct(c['high'], 1)}]"
    return f"{_pct(c['mean'], 1)} {interval} (n={c['n']}{notes})"


def _shares(s: dict) -> str:
    if s["n"] == 0:
        return "no tests here"
    return f"{_pct(s['hand'])} / {_pct(s['tool'])} / {_pct(s['vocal'])} (n={s['n']} tests)"


def _check_page_numbers(page: str, summary: dict, first_column: int) -> None:
    """The paper table's cells of each group (from `first_column` on), and the trials table,
    printed from the summary."""
    for k, group in enumerate(summary["groups"]):
        g = summary["by_group"][group]
        col = first_column + k
        competence = g["competence"]
        cell = _row(page, "Normalised competence, all rings (mean over trials)")[col]
        assert cell == _competence(competence["all"])
        for ring in (1, 2, 3):
            assert _row(page, f"… ring {ring} (")[col] == _competence(competence[f"ring{ring}"])
        for label, region in (
            ("centre region", "centre"),
            ("between hand and stick limits", "between limits"),
            ("at distance 1", "distance 1"),
        ):
            assert _row(page, f"Strategy hand / tool / vocal, {label}")[col] == _shares(
                g["strategies"][region]
            )
        vocal = g["vocal"]
        assert _row(page, "Words imitated within", "(best distance)")[col] == (
            f"{_pct(vocal['share_below'])} (of {vocal['n_words']} words)"
        )
        assert _row(page, "Median best distance, toy names")[col] == _num(vocal["median_names"])
        assert _row(page, "Median best distance, distractors")[col] == _num(
            vocal["median_distractors"]
        )
        study = g["study"]
        assert _row(page, "Competence, all rings, as the study computed it")[col].startswith(
            _pct(study["competence"]["all"])
        )
        for ring in (1, 2, 3):
            cell = _row(page, f"… ring {ring}, as the study computed it")[col]
            assert cell == _pct(study["competence"][f"ring{ring}"])
    for trial in summary["trials"]:
        cells = _row(page, trial["trial"])
        assert cells[1:8] == [
            trial["group"],
            str(trial["seed"]),
            *[_pct(trial[f"competence_{k}"], 1) for k in ("all", "ring1", "ring2", "ring3")],
            _pct(trial["share_below_threshold"]),
        ]


def _check_csv(out, summary: dict) -> None:
    """summary.csv holds the JSON's per-group numbers."""
    table = pd.read_csv(out / SUMMARY_CSV_FILE, keep_default_na=False, na_values=[""])
    assert list(table.columns) == [
        "group",
        "measure",
        "statistic",
        "scope",
        "value",
        "low",
        "high",
        "n",
    ]
    for group, g in summary["by_group"].items():
        rows = table[(table["group"] == group) & (table["measure"] == "project")]
        competence = rows[rows["statistic"] == "competence"].set_index("scope")
        for scope, c in g["competence"].items():
            assert competence.loc[scope, "value"] == pytest.approx(c["mean"])
            assert competence.loc[scope, "n"] == c["n"]
        tool = rows[rows["statistic"] == "share_tool"].set_index("scope")["value"]
        for region, s in g["strategies"].items():
            if s["tool"] is not None:
                assert tool[region] == pytest.approx(s["tool"])
        study = table[(table["group"] == group) & (table["measure"] == "study")]
        value = study[(study["statistic"] == "competence") & (study["scope"] == "all")]["value"]
        assert value.iloc[0] == pytest.approx(g["study"]["competence"]["all"])


def check_summary(out, page: str, page_name: str) -> dict:
    """The summary beside `page` (the text of `out`/`page_name`) holds the page's numbers: its
    paper table's cells of each group, its trials table, and, on a comparison, its table of
    differences; summary.csv holds the same per-group numbers. Returns the summary."""
    summary = json.loads((out / SUMMARY_JSON_FILE).read_text())
    assert summary["page"] == page_name
    # Where the page's statistics were computed (their bootstrap bounds' last digits follow
    # its BLAS kernel): this machine, in the summary and on the page.
    here = provenance.short_record(provenance.machine_record())
    assert summary["computed_on"] == here
    said = f"This page's statistics were computed on {provenance.describe(here)}"
    assert said in html.unescape(re.sub(r"\s+", " ", page))
    _check_page_numbers(page, summary, first_column=2)
    if "tests" in summary:
        rows = _rows(page)
        assert summary["tests"]["columns"] in rows
        for test in summary["tests"]["rows"]:
            assert test in rows, test
    _check_csv(out, summary)
    return summary
