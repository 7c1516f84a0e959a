"""Model Babbling against SAC + HER (`playroom rl-compare`): each agent one value, the learners
paired by seed with Holm over the page's tests, a baseline of another world refused, and the
page's files from a batch and runs (the runs written by the evaluation a baseline's run
writes, of a policy that rests the arm: no RL library needed)."""

from __future__ import annotations

import dataclasses
import json

import numpy as np
import pandas as pd
import pytest
from baseline_runs import write_run
from scipy import stats

from experiments.analysis.baseline_results import collect_baselines
from experiments.analysis.results import ReportError, collect
from experiments.analysis.trial_tests import holm
from experiments.cli.main import main
from experiments.report import rl_comparison as rl
from experiments.report.ladder import Headline
from experiments.report.measures import Measure

KEY = "competence_all"


def _headline() -> list[Headline]:
    return [Headline(KEY, Measure(KEY, "all rings", "share", lambda r: r), "value", "all rings")]


def test_the_learners_are_paired_by_seed_and_holm_runs_over_every_test():
    rng = np.random.default_rng(3)
    seeds = range(8)
    shared = {s: rng.normal(0.1, 0.05) for s in seeds}  # each seed's own room
    rows = []
    for grasp, shift in (("kinematic", -0.03), ("physical", 0.0)):
        for s in seeds:
            rows.append((grasp, rl.MODEL_BABBLING, s, KEY, shared[s]))
            if s != 7:  # a run missing: its seed leaves the pairs, not the mean of the other
                rows.append((grasp, rl.SAC_HER, s, KEY, shared[s] + shift + rng.normal(0, 0.01)))
    values = pd.DataFrame(rows, columns=rl.VALUE_COLUMNS)
    tests = rl.learner_tests(values, _headline()).set_index("grasp")
    kin = tests.loc["kinematic"]
    assert kin["mb_n"] == 8 and kin["sac_n"] == 7 and kin["n_pairs"] == 7
    sac = values[(values["learner"] == rl.SAC_HER) & (values["grasp"] == "kinematic")]
    mb = values[(values["learner"] == rl.MODEL_BABBLING) & (values["grasp"] == "kinematic")]
    x, y = sac["value"].to_numpy(), mb["value"].to_numpy()[:7]
    assert kin["difference"] == pytest.approx((x - y).mean())
    assert kin["p"] == pytest.approx(stats.ttest_rel(x, y).pvalue)
    # Paired, the seeds' shared spread (sd 0.05) leaves the 3-point shift clear.
    assert kin["high"] < 0 and kin["p"] < 0.01
    assert tests.loc["physical", "p"] > 0.01
    assert list(tests["holm_p"]) == pytest.approx(list(holm(list(tests["p"]))))


@pytest.fixture(scope="module")
def sac_runs(tmp_path_factory, batches):
    """Resting-policy runs of the world of the `batches` fixture's kinematic trials."""
    root = tmp_path_factory.mktemp("sac")
    for seed in (0, 1):
        write_run(root, seed, steps=300, placements=3)
    return root


def test_a_baseline_of_another_world_is_refused(batches, sac_runs, tmp_path):
    mb = collect(batches["kinematic"])
    baselines = collect_baselines(sac_runs)
    assert rl.paired_learners(mb, baselines).configs == mb.configs
    longer = {**mb.configs["kinematic"]}
    longer["trial"] = {**longer["trial"], "iterations": 600}
    with pytest.raises(ReportError, match="trial.iterations is 300 for them and 600"):
        rl.paired_learners(dataclasses.replace(mb, configs={"kinematic": longer}), baselines)
    physical = collect(batches["physical"])
    with pytest.raises(ReportError, match="no kinematic trials"):
        rl.paired_learners(physical, baselines)
    # Runs of two worlds under one grasp are refused when read.
    write_run(tmp_path, 0, steps=300, placements=3)
    write_run(tmp_path, 1, steps=30, placements=3)
    with pytest.raises(ReportError, match="its world differs"):
        collect_baselines(tmp_path)


def test_the_page_gives_every_agent_and_every_test(batches, sac_runs, tmp_path, capsys):
    out = tmp_path / "page"
    args = [str(batches["kinematic"]), str(sac_runs), "--out", str(out)]
    assert main(["rl-compare", *args, "--study-reference-commands", "30", "--workers", "1"]) == 0
    page = (out / "rl-compare.md").read_text()
    assert capsys.readouterr().out.startswith(page)
    record = json.loads((out / "rl-compare.json").read_text())
    values = pd.DataFrame(record["values"])
    mine = values[values["key"] == KEY].set_index(["learner", "seed"])["value"]
    # Each agent's value is its own eval.json's.
    for learner, folder in ((rl.MODEL_BABBLING, batches["kinematic"]), (rl.SAC_HER, sac_runs)):
        for d in sorted(p for p in folder.iterdir() if (p / "eval.json").is_file()):
            summary = json.loads((d / "eval.json").read_text())
            assert mine[(learner, summary["seed"])] == pytest.approx(summary["competence"]["all"])
    tests = pd.read_csv(out / "rl-compare.csv")
    assert len(tests) == len(record["measures"])
    competence = tests[tests["key"].str.startswith("competence_")]
    assert list(competence["n_pairs"]) == [2, 2, 2, 2]
    assert "| kinematic | SAC + HER | 2 | 0, 1 | 300 |" in page
    assert set(record["study"]["kinematic"]) == {rl.MODEL_BABBLING, rl.SAC_HER}
    assert (out / "rl-compare.png").read_bytes().startswith(b"\x89PNG")


def test_a_folder_without_runs_is_refused_in_one_line(batches, tmp_path, capsys):
    args = [str(batches["kinematic"]), str(tmp_path), "--out", str(tmp_path / "page")]
    assert main(["rl-compare", *args]) == 2
    err = capsys.readouterr().err.strip()
    assert "no baseline runs found" in err and "\n" not in err
    assert not (tmp_path / "page").exists()
