"""Reports of a batch (`experiments.report.batch_report`, `.comparison`, `.results`, `.statistics`,
`.paper`): files, embedded figures, statistics checked by hand, the paper's numbers beside
ours, escaped HTML, and bad input refused with one line and nothing written."""

from __future__ import annotations

import base64
import dataclasses
import html
import json
import math
import re
import shutil
from importlib import resources
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from old_trials import as_before_eval_checksums, as_before_manifests
from page_checks import check_explained
from summary_checks import check_summary
from trial_recompute import check_trials_file

from experiments.analysis.curves import curve_rows, tool_numbers
from experiments.analysis.results import ReportError, collect
from experiments.analysis.stats import (
    cost_per_iteration,
)
from experiments.batch_files import COMPARISON_FILE, REPORT_FILE
from experiments.measure.for_reports import room_measures
from experiments.report import figures, paper
from experiments.report.batch_report import write_report
from experiments.report.comparison import write_comparison
from experiments.trial_dir import storage
from experiments.trial_dir.config_file import trial_identity
from experiments.trial_dir.layout import CHUNK_IDENTITY_KEY, EVAL_FILE

DATA_URI = re.compile(r'src="data:image/png;base64,([A-Za-z0-9+/=]+)"')


def _copy_batch(batches: dict[str, Path], target: Path, grasps=("kinematic",)) -> Path:
    for grasp in grasps:
        for trial in batches[grasp].iterdir():
            if trial.is_dir():
                shutil.copytree(trial, target / trial.name)
    return target


def _embedded(page: Path, out_dir: Path, pattern: str) -> None:
    """Every PNG written is embedded in the page, byte for byte, and nothing else is."""
    pngs = sorted(out_dir.glob(pattern))
    uris = DATA_URI.findall(page.read_text())
    assert len(pngs) >= 5
    assert len(uris) == len(pngs)
    assert sorted(base64.b64decode(u) for u in uris) == sorted(p.read_bytes() for p in pngs)
    for png in pngs:
        assert png.read_bytes().startswith(b"\x89PNG")


# Collecting ----------------------------------------------------------------------------------


def test_collect_reads_every_trial_into_tables(batches):
    results = collect(batches["kinematic"])
    assert results.groups == ["kinematic"]
    assert sorted(results.trials["seed"]) == [0, 1]
    # 3 rings x 3 placements x 3 toys per trial, 6 words per trial.
    assert len(results.competence) == 2 * 27 and len(results.vocal) == 2 * 6
    assert set(results.competence["strategy"]) <= {"hand", "tool", "vocal"}
    assert set(results.curves["metric"]) >= {"tool_use", "word_recognised", "best_distance_names"}
    assert results.curves["iteration"].max() == 300
    assert results.trials["seconds"].isna().all()  # no timing.json


# Reports -------------------------------------------------------------------------------------


def test_report_writes_figures_and_embeds_them_all(batches, tmp_path):
    out = tmp_path / "report"
    page = write_report(batches["kinematic"], out, measures=room_measures(20))
    assert page == out / REPORT_FILE
    _embedded(page, out, "*.png")
    text = page.read_text()
    # The paper's numbers sit beside the batch's.
    for published in ("46%", "0.23", "0.30", "88%", "1e-72", "38% / 13% / 49%"):
        assert published in text
    assert "2 trials" in text and "this batch: kinematic" in text
    check_explained(text, n_trials_warned=True)
    assert (out / "fig4-strategies-as-the-study-computed-it.png").exists()  # study tests held
    assert "as the study computed it (paper Fig. 4)" in text
    assert "<h2>Tool use and a minimum motion</h2>" in text
    assert not list(out.glob(".*.tmp"))
    # Its numbers, machine-readable, beside it (tests/report/summary_checks.py).
    summary = check_summary(out, text, REPORT_FILE)
    assert summary["groups"] == ["kinematic"] and summary["by_group"]["kinematic"]["seeds"] == [
        0,
        1,
    ]
    assert summary["paper"]["competence_all"]["runs"] == 100


def test_comparison_puts_both_backends_side_by_side(batches, tmp_path):
    batch_b = _copy_batch(batches, tmp_path / "physical", grasps=("physical",))
    for trial in batch_b.iterdir():  # one side recorded its cost, the other did not
        (trial / "timing.json").write_text(json.dumps({"seconds": 1.5, "iterations": 300}))
    out = tmp_path / "compare"
    page = write_comparison(
        batches["kinematic"], batch_b, out, grasp_rate_commands=20, measures=room_measures(20)
    )
    assert page == out / COMPARISON_FILE
    _embedded(page, out, "comparison-*.png")
    text = page.read_text()
    assert "kinematic" in text and "physical" in text
    check_explained(text, n_trials_warned=True)
    assert "Welch t" in text and "Mann-Whitney U" in text and "χ²" in text
    assert "not recorded" in text and "5.00 ms / iteration" in text
    # In which rules the two worlds differ besides the grasp (tests/report/test_backend_rules.py).
    assert re.search(r"differ in more than the grasp rule: kinematic .*world\.catch_rule", text)
    summary = json.loads((out / "summary.json").read_text())
    assert "catch_rule" in summary["backend_rules"]["kinematic"]
    # The stick as a tool, per backend: in reach, grasps, catches, returns, held or pushed.
    for statistic in (
        "Iterations that began with the stick within reach",
        "Stick grasps per 1000 arm movements",
        "Stick returns by the experimenter per trial",
        "Tool tests (study&#39;s rule) in which the stick was only pushed",  # escaped
        "Random arm commands that grasp the stick at its start",
        # The study's tool rule beside a minimum motion (tests/report/test_tool_rule.py).
        "tests: tool share, its rule / with at least 1 mm",  # the page escapes the apostrophes
        "<h2>Tool use and a minimum motion</h2>",
    ):
        assert statistic in text, statistic
    assert (out / "comparison-stick.png").exists()
    # Where the trials ran (tests/run/test_provenance.py): all here, counted per side.
    section = text.split("<h2>Where the trials ran</h2>")[1].split("<h2>")[0]
    assert "<td>3 (kinematic 2, physical 1)</td><td>3 (kinematic 2, physical 1)</td>" in section
    # Its numbers and tests, machine-readable, beside it (tests/report/summary_checks.py).
    summary = check_summary(out, text, COMPARISON_FILE)
    assert summary["groups"] == ["kinematic", "physical"]
    assert [t["seed"] for t in summary["trials"]] == [0, 1, 0]
    assert summary["tests"]["rows"][0][0] == "Normalised competence, all rings"
    # Seeds 0, 1 against seed 0 do not pair: Welch's t over trials, each test in trial_tests.
    tests = summary["trial_tests"]
    assert tests["correction"] == "Holm" and tests["tests"]
    assert {t["method"] for t in tests["tests"]} <= {"Welch t", "one-sample t against 0"}
    assert not any(t["paired"] for t in tests["tests"])
    competence = next(t for t in tests["tests"] if t["measure"] == "competence_all")
    assert competence["n"] == {"kinematic": 2, "physical": 1} and not competence["paired"]
    assert f"This table makes {tests['count']} tests on per-trial values" in text
    # Each measure's value per trial, with its seed.
    per_trial = summary["measures"]["competence_all"]["per_trial"]
    assert list(zip(per_trial["group"], per_trial["seed"], strict=True)) == [
        ("kinematic", 0),
        ("kinematic", 1),
        ("physical", 0),
    ]
    assert per_trial["value"] == [t["competence_all"] for t in summary["trials"]]
    # Beside each t, the Mann-Whitney U test (the sides do not pair), and where the two
    # disagree on Holm's verdict; every trial's values beside the page (trial_recompute.py).
    assert {t["rank_method"] for t in tests["tests"] if len(t["n"]) == 2} == {"Mann-Whitney U"}
    assert "Where the t and the nonparametric test disagree on Holm's verdict" in text
    trials = check_trials_file(out, text, tests["tests"])
    pairs = zip(per_trial["group"], per_trial["seed"], strict=True)
    assert list(zip(trials["group"], trials["seed"], strict=True)) == list(pairs)


# Report numbers on hand-made tables ------------------------------------------------------------


def test_cost_per_iteration_and_competence_grid():
    trials = pd.DataFrame({"seconds": [2.0, 4.0, np.nan], "timed_iterations": [100, 100, np.nan]})
    assert cost_per_iteration(trials) == pytest.approx(0.03)
    assert math.isnan(cost_per_iteration(trials.iloc[2:]))
    rows = pd.DataFrame(
        {
            "x": [0.1, 0.15, -0.9],
            "y": [0.1, 0.12, -0.9],
            "error": [1.0, 2.0, 1.0],
            "random_error": [2.0, 4.0, 1.0],
        }
    )
    edges, grid, counts = figures.competence_map_grid(rows, n_bins=4)
    assert counts.sum() == 3
    assert grid[2, 2] == pytest.approx(1 - 3.0 / 6.0)  # cell [0, 0.5)^2: two tests
    assert grid[0, 0] == pytest.approx(0.0)
    assert np.isnan(grid[3, 3])


# Bad input ------------------------------------------------------------------------------------


def _refused(batch: Path, tmp_path: Path, *words: str) -> None:
    out = tmp_path / "out"
    with pytest.raises(ReportError) as info:
        write_report(batch, out, measures=room_measures(10))
    message = str(info.value)
    assert "\n" not in message
    for word in words:
        assert word in message
    assert not out.exists()


def test_empty_directory_is_refused(tmp_path):
    (tmp_path / "empty").mkdir()
    _refused(tmp_path / "empty", tmp_path, "no trial directories found")


def test_trial_without_evaluation_is_named(batches, tmp_path):
    batch = _copy_batch(batches, tmp_path / "batch")
    (batch / "kinematic-random-seed0001" / EVAL_FILE).unlink()
    _refused(batch, tmp_path, "kinematic-random-seed0001", "eval.json")


def test_mismatched_configs_name_the_field(batches, tmp_path):
    batch = _copy_batch(batches, tmp_path / "batch")
    path = batch / "kinematic-random-seed0001" / "config.json"
    config = json.loads(path.read_text())
    config["world"]["stick_length"] = 0.3
    path.write_text(json.dumps(config))
    _refused(batch, tmp_path, "world.stick_length", "mismatched")


def test_comparison_of_bad_batches_writes_nothing(batches, tmp_path):
    (tmp_path / "empty").mkdir()
    out = tmp_path / "out"
    with pytest.raises(ReportError):
        write_comparison(batches["kinematic"], tmp_path / "empty", out, measures=room_measures(10))
    # One batch with both backends compares with itself; with one backend it cannot.
    with pytest.raises(ReportError, match="exactly two groups"):
        write_comparison(
            batches["kinematic"], batches["kinematic"], out, measures=room_measures(10)
        )
    assert not out.exists()


def test_a_batch_of_both_backends_holds_two_groups(batches, tmp_path):
    batch = _copy_batch(batches, tmp_path / "both", grasps=("kinematic", "physical"))
    results = collect(batch)
    assert results.groups == ["kinematic", "physical"]
    physical = results.select("physical")
    assert physical.groups == ["physical"] and set(physical.competence["group"]) == {"physical"}
    assert len(physical.trials) == 1


# The paper's numbers and the page's HTML --------------------------------------------------------


def _spellings(value: float) -> set[str]:
    """How the paper may write a number: 46%, 0.30, 500, 10^{-72}."""
    if value >= 1:
        return {f"{value:g}"}
    if value >= 0.01:
        return {f"{value:g}", f"{value:.2f}", f"{round(100 * value)}%"}
    return {f"10^{{{round(math.log10(value))}}}"}


def _leaves(value) -> list[float]:
    if isinstance(value, dict):
        return [x for v in value.values() for x in _leaves(v)]
    if isinstance(value, list):
        return [x for v in value for x in _leaves(v)]
    return [float(value)]


def test_paper_numbers_load_from_the_data_file_each_with_its_source():
    numbers = paper.load()  # the packaged experiments/report/data/paper.json
    assert {"competence_all", "strategy_distance_1", "words_below_threshold"} <= set(numbers)
    assert numbers["competence_all"].value == 0.46
    assert numbers["median_names"].value == 0.23 and numbers["median_distractors"].value == 0.3
    for number in numbers.values():
        assert number.source.startswith("Forestier & Oudeyer 2017, section Results"), number
        assert number.text and number.quote
        # Every value is one the paper's own words state: an edit to one shows in the other.
        for leaf in _leaves(number.value):
            assert any(w in number.quote for w in _spellings(leaf)), (number.key, leaf)


def test_a_paper_number_without_its_source_is_refused(tmp_path):
    raw = json.loads(
        resources.files("experiments.report").joinpath("data", "paper.json").read_text()
    )
    del raw["numbers"]["median_names"]["source"]
    path = tmp_path / "paper.json"
    path.write_text(json.dumps(raw))
    with pytest.raises(ValueError, match="median_names lacks source"):
        paper.load(path)


def _row(page: str, first_cell: str) -> list[str]:
    """The cells (unescaped text) of the table row whose first cell starts with first_cell."""
    for row in re.findall(r"<tr>(.*?)</tr>", page, flags=re.S):
        cells = [html.unescape(c) for c in re.findall(r"<td>(.*?)</td>", row, flags=re.S)]
        if cells and cells[0].startswith(first_cell):
            return cells
    raise AssertionError(f"no row {first_cell!r}")


def test_report_shows_the_papers_number_beside_ours(batches, tmp_path, monkeypatch):
    results = collect(batches["kinematic"])
    page = write_report(
        batches["kinematic"], tmp_path / "report", measures=room_measures(20)
    ).read_text()
    published = paper.published()
    result, theirs, ours = _row(page, "Normalised competence, all rings")
    assert theirs == published["competence_all"].cell
    assert theirs == "46% better than random on average (from 100 runs)"
    assert ours.startswith(f"{100 * results.trials['competence_all'].mean():.1f}% [95% CI ")
    names = results.vocal.loc[results.vocal["is_name"], "best_distance"]
    assert _row(page, "Median best distance, toy names")[1:] == [
        "0.23 (from 500 runs)",
        f"{names.median():.2f}",
    ]
    # Beside the study's test on pooled words, the same question over trials.
    gaps = [
        t.loc[~t["is_name"], "best_distance"].median()
        - t.loc[t["is_name"], "best_distance"].median()
        for _, t in results.vocal.groupby("trial")
    ]
    over_trials = _row(page, "Names vs distractors over trials")[2]
    assert over_trials.startswith(f"{np.mean(gaps):.3f}, p = ")
    assert over_trials.endswith(f"(n={len(gaps)} trials)")
    # The paper column is read from the data file, not written into the code.
    edited = dataclasses.replace(published["competence_all"], text="12% <b>edited</b>")
    monkeypatch.setattr(paper, "published", lambda: {**published, "competence_all": edited})
    page = write_report(
        batches["kinematic"], tmp_path / "edited", measures=room_measures(20)
    ).read_text()
    assert _row(page, "Normalised competence, all rings")[1] == "12% <b>edited</b> (from 100 runs)"


def test_labels_and_paths_reach_the_page_as_text_not_markup(batches, tmp_path):
    batch = _copy_batch(batches, tmp_path / "<b>batch")
    for config_path in batch.glob("*/config.json"):
        as_before_manifests(config_path.parent)  # edited by hand below: as an older trial
        as_before_eval_checksums(config_path.parent)  # and its evaluation
        config = json.loads(config_path.read_text())
        config["trial"]["grasp"] = "<script>alert(1)</script>"
        config_path.write_text(json.dumps(config))
        summary = storage.read_json(config_path.parent / EVAL_FILE)
        storage.write_json(
            config_path.parent / EVAL_FILE, {**summary, "grasp": "<script>alert(1)</script>"}
        )
        # Log chunks carry their trial's identity: this trial's chunks take the new one.
        for chunk in config_path.parent.glob("log/*/*.parquet"):
            table = pd.read_parquet(chunk)
            table.attrs[CHUNK_IDENTITY_KEY] = trial_identity(config)
            table.to_parquet(chunk)
    text = write_report(batch, tmp_path / "out", measures=room_measures(20)).read_text()
    assert "<script>" not in text and "<b>batch" not in text
    assert "this batch: &lt;script&gt;alert(1)&lt;/script&gt;" in text
    assert "&lt;b&gt;batch" in text


def test_stick_numbers_of_a_hand_made_log():
    log = pd.DataFrame(
        {
            "iteration": range(4),
            "motor_space": ["arm", "arm", "voice", "arm"],
            "stick_grasped": [True, False, False, True],
            "toy1_moved_by": ["stick", "", "", "hand"],
            "toy2_moved_by": "",
            "toy3_moved_by": "",
            "word_recognised": "",
            "stick_distance": [0.3, 0.7, 0.7, 0.2],
            "stick_returned": [False, True, False, False],
        }
    )
    numbers = tool_numbers(log, reach=0.6)
    assert numbers["stick_grasps_per_1000_arm"] == pytest.approx(2000 / 3)
    assert numbers["toy_catches_per_1000_arm"] == pytest.approx(1000 / 3)
    assert numbers["stick_in_reach"] == 0.5 and numbers["stick_returns"] == 1
    curves = curve_rows(log, pd.DataFrame(), iterations=4, names=set(), reach=0.6)
    in_reach = curves[curves["metric"] == "stick_in_reach"]["value"]
    assert list(in_reach) == [0.5]


@pytest.mark.slow  # over 5 s: make test-slow runs it
def test_the_study_reference_is_played_once_and_kept(batches, tmp_path, monkeypatch):
    from experiments.measure import study_measure

    monkeypatch.setenv(study_measure.CACHE_ENV, str(tmp_path / "cache"))
    batch = _copy_batch(batches, tmp_path / "batch")
    first = write_report(batch, tmp_path / "one", measures=room_measures(20)).read_text()
    # Kept in the cache directory, not in the batch the report only reads.
    assert len(list((tmp_path / "cache").glob("study-reference-*.parquet"))) == 1
    assert not list(batch.glob("study-reference-*"))

    def played(*args, **kwargs):
        raise AssertionError("the kept reference should have been read back")

    monkeypatch.setattr(study_measure, "random_reference", played)
    second = write_report(batch, tmp_path / "two", measures=room_measures(20)).read_text()
    assert "as the study computed it" in first
    rows = [line for line in first.splitlines() if "as the study computed it" in line]
    assert rows == [line for line in second.splitlines() if "as the study computed it" in line]
