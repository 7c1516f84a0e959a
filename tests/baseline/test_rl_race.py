"""The race's machinery at a tiny scale (`playroom rl-race`, experiments/baseline/race_run.py):
every learner tested on the same held-out toy goals at the same budgets, success near, far and in
all; Model Babbling's agent tested at each budget is the one a trial run to that budget has; a
run done is skipped and a stopped one goes on to the same curve; other settings are refused in
one line. Nothing here says who wins: the full race does (docs/rl-race.md)."""

from __future__ import annotations

import gymnasium
import numpy as np
import pandas as pd
import pytest
from rl_extra import require_stable_baselines3

import sim.envs  # noqa: F401  (registers the ids)
from experiments.baseline import race_learners as rl
from experiments.baseline.control_settings import RANDOM_COMMANDS_PER_GOAL
from experiments.baseline.race_run import COLUMNS, run_model_babbling
from experiments.baseline.race_settings import (
    LEARNERS,
    MODEL_BABBLING,
    RACE_CONFIG,
    RANDOM_COMMANDS,
    race_runs,
)
from experiments.cli.main import main
from experiments.measure.evaluation import GOAL_TIMES

TINY = ["--seeds", "1", "--iterations", "200", "--every", "100", "--eval-goals", "10"]
TINY += ["--grasps", "kinematic", "--workers", "1"]


def test_the_held_out_goals_are_the_same_whatever_the_motor_space():
    arm = gymnasium.make(rl.toys_goal_id("kinematic"))
    both = gymnasium.make(rl.toys_goal_id("kinematic"), motor="both")
    for seed in range(1_000_000, 1_000_020):
        (a, info_a), (b, info_b) = arm.reset(seed=seed), both.reset(seed=seed)
        np.testing.assert_array_equal(a["desired_goal"], b["desired_goal"])
        assert (info_a["toy"], info_a["ring"]) == (info_b["toy"], info_b["ring"])


def test_model_babblings_goal_is_the_toys_straight_way_to_the_point():
    way = rl.trajectory_toward(np.array([0.2, -0.4]), np.array([0.6, 0.0]))
    np.testing.assert_allclose(way[[0, 4, 5, 9]], [0.2, 0.6, -0.4, 0.0])
    np.testing.assert_allclose(way[:5], 0.2 + 0.4 * GOAL_TIMES)


@pytest.mark.slow
def test_the_tiny_race_tests_every_learner_on_the_same_goals_and_resumes(tmp_path, capsys):
    require_stable_baselines3()
    out = tmp_path / "race"
    assert main(["rl-race", "--out", str(out), *TINY]) == 0
    table = pd.read_csv(out / "rl-race.csv")
    assert list(table.columns) == COLUMNS
    assert set(table["learner"]) == set(LEARNERS) and set(table["steps"]) == {100, 200}
    everyone = table[table["ring"] == "all"].set_index("learner")["goals"]
    assert (everyone.drop(RANDOM_COMMANDS) == 10).all()
    assert (everyone[RANDOM_COMMANDS] == 10 * RANDOM_COMMANDS_PER_GOAL).all()
    # The same goals for every learner: as many near and far for each (random commands try
    # each goal RANDOM_COMMANDS_PER_GOAL times).
    rings = table[table["ring"] != "all"].copy()
    rings.loc[rings["learner"] == RANDOM_COMMANDS, "goals"] //= RANDOM_COMMANDS_PER_GOAL
    by_ring = rings.groupby(["learner", "ring"])["goals"].first().unstack()
    assert (by_ring.nunique() == 1).all() and by_ring.sum(axis=1).eq(10).all()
    chance = table[table["learner"] == RANDOM_COMMANDS].groupby("ring")["success"].nunique()
    assert (chance == 1).all()  # nothing learns: the same share at every budget
    claims = pd.read_csv(out / "rl-race-claims.csv")
    assert set(claims["learner"]) == set(LEARNERS) - {MODEL_BABBLING}
    assert (claims["claim"] == "no difference shown").all()  # one seed claims nothing
    assert (out / "rl-race.png").read_bytes()[:4] == b"\x89PNG"
    capsys.readouterr()

    # Model Babbling's agent at 100 is that of a trial asked for 100 from the start.
    (run,) = race_runs(RACE_CONFIG, [MODEL_BABBLING], 1, 100, ["kinematic"], 100, 10)
    alone, _ = run_model_babbling(run, tmp_path / "alone" / "trial")
    mine = table[(table["learner"] == MODEL_BABBLING) & (table["steps"] == 100)]
    assert mine["success"].tolist() == [r["success"] for r in alone]

    # Stopped after its first test: the same command goes on to the same curve.
    name = "model-babbling-kinematic-seed0000"
    for path in (
        out / "runs" / f"{name}.json",
        out / "trials" / "kinematic-seed0000-tests" / "00000200.csv",
    ):
        path.unlink()
    assert main(["rl-race", "--out", str(out), *TINY]) == 0
    done = capsys.readouterr().out
    assert f"{name} done" in done and "sac-her-kinematic-seed0000 done" not in done
    pd.testing.assert_frame_equal(pd.read_csv(out / "rl-race.csv"), table)

    assert main(["rl-race", "--out", str(out), *TINY, "--eval-goals", "20"]) == 2
    (line,) = capsys.readouterr().err.strip().splitlines()
    assert "other settings" in line


def test_a_budget_that_does_not_divide_the_movements_is_refused_in_one_line(tmp_path, capsys):
    require_stable_baselines3()
    assert main(["rl-race", "--out", str(tmp_path / "r"), *TINY, "--every", "150"]) == 2
    (line,) = capsys.readouterr().err.strip().splitlines()
    assert "multiple of the tests' period (150)" in line
    assert not (tmp_path / "r").exists()
