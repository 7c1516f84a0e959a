"""Ablation tables (`playroom ablations`): rows paired by seed against a baseline, labelled by
the settings that changed, numbers checked against the trials' own files, bad input refused
with one line and nothing written."""

from __future__ import annotations

import dataclasses
import json
import math
import shutil
from importlib import resources
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from scipy import stats

from experiments.analysis.results import ReportError
from experiments.analysis.stats import paired_difference
from experiments.batch_files import ABLATION_CSV_FILE, ABLATION_FIGURE_FILE, ABLATION_TABLE_FILE
from experiments.measure.evaluation import EvaluationSettings
from experiments.measure.for_reports import room_measures
from experiments.measure.trial_evaluation import evaluate_trial
from experiments.report.ablations import ablation_rows, write_ablations
from experiments.report.trial_data import read_trial_data
from experiments.run.settings import TrialSettings
from experiments.run.trial import run_trial
from experiments.trial_dir.config_file import config_differences

COMMANDS = 20  # random commands per ring behind the study's measure: enough to compute it


@pytest.fixture(scope="module")
def sigma_batch(tmp_path_factory) -> Path:
    """The kinematic batch's seeds 0 and 1 again, with the exploration noise halved."""
    batch = tmp_path_factory.mktemp("ablation") / "sigma"
    for seed in (0, 1):
        trial = batch / f"kinematic-random-seed{seed:04d}"
        settings = TrialSettings(
            grasp="kinematic",
            iterations=300,
            seed=seed,
            checkpoint_every=300,
            overrides={"learner": {"exploration_sigma": 0.05}},
        )
        run_trial(trial, settings, progress=False)
        evaluate_trial(trial, EvaluationSettings(n_placements=3))
    return batch


def _competence(batch: Path) -> dict[int, float]:
    """competence_all per seed, read from the trials' eval.json."""
    out = {}
    for trial in batch.glob("*-seed*"):
        seed = json.loads((trial / "config.json").read_text())["trial"]["seed"]
        out[seed] = json.loads((trial / "eval.json").read_text())["competence"]["all"]
    return out


def _gaps(batch: Path) -> dict[int, float]:
    """Each trial's median best distance of its distractors minus its names', per seed."""
    out = {}
    for trial in batch.glob("*-seed*"):
        seed = json.loads((trial / "config.json").read_text())["trial"]["seed"]
        vocal = pd.read_parquet(trial / "vocal.parquet")
        medians = vocal.groupby("is_name")["best_distance"].median()
        out[seed] = medians[False] - medians[True]
    return out


def test_rows_are_paired_by_seed_and_named_by_the_changed_setting(batches, sigma_batch, tmp_path):
    base, ablated = _competence(batches["kinematic"]), _competence(sigma_batch)
    rows = ablation_rows(batches["kinematic"], [sigma_batch], room_measures(COMMANDS))
    assert [row.label for row in rows] == [
        "baseline (kinematic)",
        "learner.exploration_sigma: 0.1 -> 0.05",
    ]
    baseline, row = rows
    competence = row.measures["competence_all"]
    assert baseline.n_trials == row.n_trials == competence.n_pairs == 2
    assert math.isnan(baseline.measures["competence_all"].difference)
    differences = [ablated[s] - base[s] for s in (0, 1)]
    assert competence.difference == pytest.approx(np.mean(differences))
    assert competence.mean == pytest.approx(np.mean(list(ablated.values())))
    vocal = pd.concat(pd.read_parquet(t / "vocal.parquet") for t in sigma_batch.glob("*-seed*"))
    # Each trial's share of its words, averaged over trials (6 words each: the pooled share).
    within = (vocal["best_distance"] < 0.4).mean()
    assert row.measures["words_within"].mean == pytest.approx(within)
    names = vocal.loc[vocal["is_name"], "best_distance"]
    assert row.median_names == pytest.approx(np.median(names))
    # Each trial's gap, distractors' median minus names', against the baseline's on its seed.
    assert set(row.measures) == {"competence_all", "words_within", "names_vs_distractors"}
    gap, gap_base = _gaps(sigma_batch), _gaps(batches["kinematic"])
    names_gap = row.measures["names_vs_distractors"]
    assert names_gap.mean == pytest.approx(np.mean(list(gap.values())))
    assert names_gap.difference == pytest.approx(np.mean([gap[s] - gap_base[s] for s in (0, 1)]))
    assert 0.0 <= row.study_competence <= 1.0
    assert set(row.study_strategies) == {"centre", "between_limits", "distance_1"}


def test_the_baseline_keeps_only_the_seeds_the_ablations_hold(batches, sigma_batch, tmp_path):
    one_seed = tmp_path / "seed1"
    shutil.copytree(sigma_batch / "kinematic-random-seed0001", one_seed / "k-seed0001")
    baseline, row = ablation_rows(batches["kinematic"], [one_seed], room_measures(COMMANDS))
    competence = row.measures["competence_all"]
    assert baseline.n_trials == row.n_trials == competence.n_pairs == 1
    base, ablated = _competence(batches["kinematic"]), _competence(sigma_batch)
    assert baseline.measures["competence_all"].mean == pytest.approx(base[1])
    assert competence.difference == pytest.approx(ablated[1] - base[1])
    assert math.isnan(competence.p) and math.isnan(competence.holm_p)  # one pair: no test


def test_files_are_written_with_every_row(batches, sigma_batch, tmp_path):
    table = write_ablations(
        batches["kinematic"], [sigma_batch], tmp_path / "out", measures=room_measures(COMMANDS)
    )
    assert table.name == ABLATION_TABLE_FILE
    lines = table.read_text().splitlines()
    assert "learner.exploration_sigma: 0.1 -> 0.05" in lines[3] and lines[4] == ""
    assert "survives Holm's correction" in lines[5]
    csv = pd.read_csv(tmp_path / "out" / ABLATION_CSV_FILE)
    assert list(csv["n_trials"]) == [2, 2]
    columns = {"competence_all_difference", "competence_all_p", "competence_all_holm_p"}
    columns |= {"names_vs_distractors_within_p", "study_distance_1_vocal"}
    assert columns <= set(csv.columns)
    # The names effect's p: the study's convention, named in the column and the header.
    vocal = pd.concat(pd.read_parquet(t / "vocal.parquet") for t in sigma_batch.glob("*-seed*"))
    names, distractors = (vocal.loc[vocal["is_name"] == s, "best_distance"] for s in (True, False))
    one_sided = min(
        stats.mannwhitneyu(names, distractors, alternative=side).pvalue
        for side in ("less", "greater")
    )
    p = csv["pooled_names_vs_distractors_p_two_sided"].iloc[1]
    assert p == pytest.approx(min(1, 2 * one_sided))
    assert "Mann-Whitney two-sided p, one-sided doubled as the study" in lines[0]
    assert (tmp_path / "out" / ABLATION_FIGURE_FILE).read_bytes().startswith(b"\x89PNG")
    # Every trial of every row, with who computed it (the trials' provenance.json, eval.json).
    trials = read_trial_data(tmp_path / "out" / "ablations-trials.csv")
    assert list(zip(trials["batch"], trials["seed"], strict=True)) == [
        ("kinematic", 0),
        ("kinematic", 1),
        ("sigma", 0),
        ("sigma", 1),
    ]
    assert list(trials["baseline"]) == [True, True, False, False]
    assert trials["computed_commit"].str.fullmatch(r"[0-9a-f]{7}(\+dirty)?").all()
    assert trials["computed_on"].str.contains("from iteration 0").all()
    assert trials["evaluated_on"].ne("not recorded").all()
    assert list(trials["competence_all"][2:]) == [_competence(sigma_batch)[s] for s in (0, 1)]


def test_batches_that_cannot_be_paired_are_refused_and_nothing_is_written(batches, tmp_path):
    out = tmp_path / "out"
    with pytest.raises(ReportError, match="none in common"):
        write_ablations(
            batches["kinematic"], [batches["physical"]], out, measures=room_measures(COMMANDS)
        )
    other_seed = tmp_path / "seed7"
    trial = other_seed / "kinematic-random-seed0007"
    run_trial(trial, TrialSettings(iterations=200, seed=7, checkpoint_every=200), progress=False)
    evaluate_trial(trial, EvaluationSettings(n_placements=3))
    with pytest.raises(ReportError, match="shares no seed"):
        write_ablations(batches["kinematic"], [other_seed], out, measures=room_measures(COMMANDS))
    with pytest.raises(ReportError, match="at least one batch"):
        write_ablations(batches["kinematic"], [], out, measures=room_measures(COMMANDS))
    assert not out.exists()


def test_paired_difference_is_the_one_sample_test_of_the_differences():
    a, b = np.array([1.0, 2.0, 3.0, 5.0]), np.array([0.0, 2.0, 1.0, 1.0])
    mean, low, high, p = paired_difference(a, b)
    d = a - b
    half = stats.t.ppf(0.975, 3) * d.std(ddof=1) / 2.0
    assert mean == 1.75
    assert (low, high) == pytest.approx((1.75 - half, 1.75 + half))
    assert p == pytest.approx(stats.ttest_1samp(d, 0.0).pvalue)
    assert math.isnan(paired_difference(a, a + 1.0)[3])  # no variance: no test


def test_the_command_prints_the_table_and_names_a_bad_batch(batches, sigma_batch, tmp_path, capsys):
    from experiments.cli.main import main

    args = [str(batches["kinematic"]), str(sigma_batch), "--out", str(tmp_path / "out")]
    assert main(["ablations", *args, "--study-reference-commands", str(COMMANDS)]) == 0
    printed = capsys.readouterr().out
    assert "learner.exploration_sigma: 0.1 -> 0.05" in printed and "ablations.png" in printed
    missing = tmp_path / "missing"
    assert main(["ablations", str(batches["kinematic"]), str(missing), "--out", "x"]) == 2
    assert str(missing) in capsys.readouterr().err


def test_each_ablation_config_changes_one_setting_of_its_preset(installed_generated_map):
    """The shipped ablations: `NAME.json` switches one study setting back to the project's,
    `project-plus-NAME.json` switches the same setting of the project preset to the study's,
    `project.json` is the project preset's baseline; `diva.json` gives the study preset the
    study's own vocal tract (no preset has it: its data is the user's); all on the
    replication's first seeds."""
    from experiments.batches.spec import load_spec
    from experiments.run.trial_config import full_config

    folder = resources.files("experiments.batches").joinpath("ablations")
    files = sorted((f for f in folder.iterdir() if f.name.endswith(".json")), key=lambda f: f.name)
    assert len(files) >= 3, f"no shipped ablation configs in {folder}"
    names = {f.name.removesuffix(".json") for f in files}
    assert {f"project-plus-{n}" for n in names - {"diva"} if not n.startswith("project")} <= names
    for path in files:
        spec = load_spec(config_file=Path(str(path)))
        assert spec.seeds == tuple(range(32)) and spec.iterations == 80000
        (name, settings), *_ = spec.trials()
        preset = dataclasses.replace(settings, overrides={})
        changes = config_differences(full_config(preset), full_config(settings))
        changes = [c for c in changes if not c[0].startswith("trial.overrides")]
        stem = path.name.removesuffix(".json")
        if stem == "project":
            assert settings.preset == "project" and changes == []
            continue
        if stem == "diva":
            assert settings.preset == "study" and settings.voice == "diva" and changes == []
            vtl = full_config(dataclasses.replace(settings, voice="vtl"))
            changes = config_differences(vtl, full_config(settings))
            assert [c[0] for c in changes] == ["trial.voice", "world.voice"]
            continue
        assert settings.preset == ("project" if stem.startswith("project") else "study")
        assert len(changes) == 1, f"{path.name} changes {changes}"
        key, _, value = changes[0]
        other = "study" if settings.preset == "project" else "project"
        other_config = full_config(dataclasses.replace(settings, preset=other, overrides={}))
        section, field = key.split(".")
        assert other_config[section][field] == value, f"{path.name}: not the {other}'s value"
