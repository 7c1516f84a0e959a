"""The positive control with its library (the `rl` extra): a short run of its learner on the
hand goal reaches held-out goals far more often than random arm commands do, the same seed
gives the same curve, the nearest outcome looks among the learner's own movements, and
`playroom rl-control` writes the curves, skips the runs done and refuses other settings."""

from __future__ import annotations

import gymnasium
import numpy as np
import pandas as pd
import pytest
from rl_extra import require_stable_baselines3

require_stable_baselines3()

from experiments.baseline import control_learner as cl  # noqa: E402
from experiments.baseline.control_run import COLUMNS, goal_id, run_one  # noqa: E402
from experiments.baseline.control_settings import (  # noqa: E402
    LEARNER,
    NEAREST,
    RANDOM,
    ControlSettings,
    library_defaults,
)
from experiments.cli.main import main  # noqa: E402
from experiments.trial_dir import storage  # noqa: E402

pytestmark = pytest.mark.slow

# The short run: 6000 movements (1000 random ones, then 5000 gradient steps), tested on 100
# held-out goals. Measured with seed 0 on the 2-core development machine (2026-11-28): the
# learner reached 79% of them, random arm commands 3.6% (94 s). The margin asked leaves room
# for another machine's arithmetic, which changes a run as another seed does: at 6000
# movements the 3 seeds of docs/rl-baseline.md's control reached 65-76% of 200 goals.
SHORT = ControlSettings("hand", seed=0, movements=6000, eval_every=6000, eval_goals=100)
MARGIN = 0.3


def test_a_short_run_learns_the_hand_goal_far_beyond_random_arm_commands():
    table, record = run_one(SHORT)
    last = table[table["steps"] == SHORT.movements].set_index("learner")["success"]
    assert last[LEARNER] - last[RANDOM] >= MARGIN
    assert last[NEAREST] >= 0.9  # the movements it was given held the answers
    untrained = table[(table["steps"] == 0) & (table["learner"] == LEARNER)]["success"]
    assert float(untrained.iloc[0]) < last[RANDOM] + 0.1
    assert record["settings"]["goal"] == "hand" and record["env_id"] == "PlayroomHandGoal-v1"


def test_the_same_seed_gives_the_same_curve():
    settings = ControlSettings("stick", seed=1, movements=1500, eval_every=750, eval_goals=20)
    first, _ = run_one(settings)
    again, _ = run_one(settings)
    pd.testing.assert_frame_equal(first, again)
    assert list(first.columns) == COLUMNS


def test_the_nearest_outcome_replays_the_learners_own_movement_nearest_the_goal():
    env = gymnasium.make(goal_id("hand", "kinematic"))
    model = cl.sac_her(env, seed=0, threads=1)
    model.learn(50)  # random movements (learning starts later): the buffer's 50
    buffer = model.replay_buffer
    achieved = buffer.next_observations["achieved_goal"][:50, 0]
    observation, _ = env.reset(seed=3, options={"desired_goal": achieved[17] + 1e-4})
    np.testing.assert_array_equal(cl.nearest_outcome_act(model)(observation), buffer.actions[17, 0])
    # Replayed in another room, the same command brings the hand to the same point.
    _, reward, *_ = env.step(buffer.actions[17, 0])
    assert reward == 0.0


def test_the_records_defaults_are_stable_baselines3s_own():
    from stable_baselines3 import SAC

    model = SAC("MultiInputPolicy", goal_id("hand", "kinematic"), buffer_size=10, device="cpu")
    defaults = library_defaults()
    assert defaults["learning_rate"] == model.learning_rate == 3e-4
    assert defaults["net_arch"] == model.policy.net_arch == [256, 256]
    assert (defaults["gamma"], defaults["learning_starts"]) == (model.gamma, model.learning_starts)


def _control(out, *more: str) -> int:
    args = ["rl-control", "--out", str(out), "--seeds", "1", "--movements", "200"]
    return main(args + ["--every", "100", "--eval-goals", "10", "--quiet", *more])


def test_the_command_writes_the_curves_skips_runs_done_and_refuses_other_settings(tmp_path, capsys):
    out = tmp_path / "control"
    assert _control(out) == 0
    table = pd.read_csv(out / "rl-control.csv")
    assert list(table.columns) == COLUMNS
    assert set(table["goal"]) == {"hand", "stick"} and set(table["steps"]) == {0, 100, 200}
    assert set(table["learner"]) == {LEARNER, NEAREST, RANDOM}
    record = storage.read_json(out / "rl-control.json")
    assert record["learner"]["net_arch"] == [64, 64]
    assert record["settings"]["settings"] == "control"
    assert record["test_goals"]["first_reset_seed"] == 1_000_000
    assert record["stable_baselines3_defaults"]["net_arch"] == [256, 256]
    assert [r["settings"]["goal"] for r in record["runs"]] == ["hand", "stick"]
    assert (out / "rl-control.png").read_bytes()[:4] == b"\x89PNG"
    capsys.readouterr()
    assert _control(out) == 0  # nothing left to run: the same curves
    assert "2 of the 2 runs are done" in capsys.readouterr().err
    pd.testing.assert_frame_equal(pd.read_csv(out / "rl-control.csv"), table)
    assert _control(out, "--eval-goals", "20") == 2  # the last one given wins
    (line,) = capsys.readouterr().err.strip().splitlines()
    assert "other settings (eval_goals 10 (asked 20))" in line
