"""The RL baseline end to end with its library (the `rl` extra): `playroom rl-baseline` trains
SAC + HER a few hundred movements on each backend, tests the policies with the project's
measure on 3 placements, and writes an evaluation of a trial's form; a stopped run resumes at
the first toy not done; a finished one, or one of other settings, is refused. Not a performance
claim: a few hundred movements teach nothing."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import pandas as pd
import pytest
from rl_extra import require_stable_baselines3

require_stable_baselines3()

from experiments.baseline.run import policy_file  # noqa: E402
from experiments.cli.main import main  # noqa: E402
from experiments.trial_dir import manifest, storage  # noqa: E402
from experiments.trial_dir.layout import BASELINE_FILE, EVALUATION_TABLES, TRAINING_FILE  # noqa: E402

pytestmark = pytest.mark.slow

DATA = Path(__file__).resolve().parents[1] / "data"
# SAC's default learning_starts is 100: 150 movements per toy are 50 gradient steps each.
STEPS, PLACEMENTS = 450, 3


def _run(out: Path, grasp: str, steps: int = STEPS) -> int:
    return main(
        ["rl-baseline", "--grasp", grasp, "--steps", str(steps), "--seed", "2"]
        + ["--placements", str(PLACEMENTS), "--out", str(out), "--quiet"]
    )


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    """One finished run per backend, made once for the module."""
    root = tmp_path_factory.mktemp("rl")
    for grasp in ("kinematic", "physical"):
        assert _run(root / grasp, grasp) == 0
    return root


@pytest.mark.parametrize("grasp", ["kinematic", "physical"])
def test_a_run_is_trained_then_evaluated_as_a_trial_is(runs, grasp):
    out = runs / grasp
    summary = storage.read_json(out / "eval.json")
    assert summary["grasp"] == grasp and summary["seed"] == 2
    assert summary["babbling"] == "sac-her" and summary["iterations"] == STEPS
    assert summary["evaluated_at_iteration"] == STEPS and summary["n_placements"] == PLACEMENTS
    assert set(summary["competence"]) == {"all", "ring1", "ring2", "ring3"}
    # The tables a trial's evaluation writes, vouched for by eval.json, of a trial's columns.
    tables = {
        name: storage.read_table(out / name, data=manifest.read_evaluation_file(out, name, summary))
        for name in EVALUATION_TABLES
    }
    trials = pd.read_parquet(DATA / "before-actors-kinematic-seed0-2000-competence.parquet")
    competence = tables["competence.parquet"]
    assert list(competence.columns) == list(trials.columns) and len(competence) == 9 * PLACEMENTS
    assert set(competence["ring"]) == {1, 2, 3}
    assert len(tables["study-tests.parquet"]) == 9 * PLACEMENTS
    assert len(tables["vocal.parquet"]) == 6
    # Each toy's policy and its record: the movements shared, SAC's and HER's defaults, where.
    training = json.loads((out / TRAINING_FILE).read_text())["toys"]
    assert sorted(training) == ["1", "2", "3"]
    assert sum(entry["steps"] for entry in training.values()) == STEPS
    for toy, entry in training.items():
        assert (
            manifest.entry_of((out / policy_file(int(toy))).read_bytes()).as_json() == entry["file"]
        )
        assert entry["her"]["n_sampled_goal"] == 4 and entry["sac"]["learning_starts"] == "100"
        assert entry["libraries"]["stable-baselines3"]
    record = json.loads((out / BASELINE_FILE).read_text())
    assert record["settings"]["grasp"] == grasp and record["trial"]["trial"]["seed"] == 2
    assert record["command"].startswith("playroom rl-baseline")


def test_a_finished_run_is_refused_and_a_stopped_one_resumes_at_its_first_toy_not_done(
    runs, tmp_path, capsys
):
    assert _run(runs / "kinematic", "kinematic") == 2
    assert "holds a finished baseline" in capsys.readouterr().err
    # As if stopped while training toy 3: its policy and entry not written, no evaluation.
    stopped = tmp_path / "stopped"
    shutil.copytree(runs / "kinematic", stopped)
    (stopped / "eval.json").unlink()
    (stopped / policy_file(3)).unlink()
    record = json.loads((stopped / TRAINING_FILE).read_text())
    done = {t: record["toys"][t] for t in ("1", "2")}
    (stopped / TRAINING_FILE).write_text(json.dumps({"toys": done}))
    assert _run(stopped, "kinematic", steps=STEPS + 3) == 2  # other settings: refused
    assert "holds a baseline of other settings (steps 450 (asked 453))" in capsys.readouterr().err
    assert _run(stopped, "kinematic") == 0
    assert "the policies of toys 1, 2 are done" in capsys.readouterr().err
    resumed = json.loads((stopped / TRAINING_FILE).read_text())["toys"]
    assert {t: resumed[t] for t in ("1", "2")} == done and "3" in resumed
    assert (stopped / "eval.json").exists()


def test_the_policies_behaviour_is_tallied_beside_random_actions(runs, tmp_path):
    table = tmp_path / "behaviour.csv"
    argv = ["rl-behaviour", str(runs / "kinematic"), "--episodes", "2", "--out", str(table)]
    assert main(argv) == 0
    rows = pd.read_csv(table)
    assert len(rows) == 6  # three toys, each by its policy and by random actions
    assert set(rows["actor"]) == {"policy", "random"} and set(rows["toy"]) == {1, 2, 3}
    assert (rows["movements"] == 6).all()  # 2 episodes of 3 movements
    assert rows[["voice", "moved", "reached"]].stack().between(0, 1).all()
    again = tmp_path / "again.csv"
    assert main([*argv[:-1], str(again)]) == 0
    pd.testing.assert_frame_equal(pd.read_csv(again), rows)  # the same episodes, the same acts
