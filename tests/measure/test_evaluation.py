"""Evaluation after learning (docs/protocol.md §10): goals, strategies, the random reference."""

from __future__ import annotations

import re
import shutil

import numpy as np
import pandas as pd
import pytest

from experiments.cli.main import main
from experiments.measure.evaluation import (
    GOAL_TIMES,
    EvaluationSettings,
    competence_table,
    goal_trajectory,
    movement_contacts,
    normalised_competence,
    strategy_of,
)
from experiments.measure.trial_evaluation import evaluate_trial
from experiments.run.trial_parts import load_trial
from models.layout import ARM_DIM
from sim import Playroom
from sim import events as ev
from sim.config import world_preset

# The world these tests were written for: the project preset (explicit, as Playroom() takes
# the default preset, the study's).
PROJECT = world_preset("project")


class RestingAgent:
    """A scripted agent whose outcome is known: its arm model is always nearer than its voice
    model, and its command keeps the arm at rest, so no toy moves."""

    def toy_models(self, toy: int) -> tuple[int, int]:
        return 2 + toy - 1, 6 + toy - 1

    def nearest_distance(self, model: int, context, goal) -> float:
        return 0.1 if model < 6 else 0.9

    def exploit(self, model: int, context, goal) -> np.ndarray:
        return np.zeros(ARM_DIM)


def test_goal_is_the_toy_moved_straight_to_the_base():
    goal = goal_trajectory(np.array([0.4, -0.2]))
    np.testing.assert_allclose(goal[:5], 0.4 * (1 - GOAL_TIMES))
    np.testing.assert_allclose(goal[5:], -0.2 * (1 - GOAL_TIMES))
    assert goal[4] == 0 and goal[9] == 0


def test_strategy_classification():
    assert strategy_of("voice", stick_moved=False) == "vocal"
    assert strategy_of("voice", stick_moved=True) == "vocal"
    assert strategy_of("arm", stick_moved=False) == "hand"
    assert strategy_of("arm", stick_moved=True) == "tool"


def test_contacts_tell_a_held_stick_from_a_pushed_one_and_name_what_moved_the_goal():
    held = [ev.Event(ev.STICK_GRASPED, 3), ev.Event(ev.STICK_MOVED, 3, obj="stick", by="hand")]
    pushed = [ev.Event(ev.STICK_MOVED, 7, obj="stick", by="push")]
    caught = [*held, ev.Event(ev.TOY_MOVED, 20, obj="toy2", by="stick")]
    brought = [ev.Event(ev.TOY_MOVED, 2, obj="toy3", by="caregiver")]
    assert movement_contacts(held, "toy1") == ("held", "none")
    assert movement_contacts(pushed, "toy1") == ("pushed", "none")
    assert movement_contacts(caught, "toy2") == ("held", "stick")
    assert movement_contacts(caught, "toy1") == ("held", "none")  # another toy's mover
    assert movement_contacts(brought, "toy3") == ("untouched", "caregiver")
    assert movement_contacts([ev.Event(ev.TOY_MOVED, 9, obj="toy1", by="push")], "toy1") == (
        "untouched",
        "push",
    )
    assert movement_contacts([], "toy1") == ("untouched", "none")


@pytest.mark.parametrize("grasp", ["kinematic", "physical"])
def test_scripted_agent_errors_match_a_hand_computation(grasp):
    room = Playroom(grasp, seed=0, config=PROJECT)
    table = competence_table(RestingAgent(), room, EvaluationSettings(n_placements=4, seed=9))
    assert len(table) == 3 * 4 * 3
    assert set(table["strategy"]) == {"hand"}
    # The resting arm holds no stick and moves a toy only where it grabs one at once.
    assert set(table["stick_contact"]) == {"untouched"}
    assert set(table["goal_moved_by"]) <= {"none", "hand"}
    assert set(table["random_goal_moved_by"]) <= {"none", "hand", "stick", "caregiver", "push"}
    # A toy at p that does not move, against the goal p (1 - t): error = |p| sqrt(sum t^2),
    # unless the resting hand (at (0, 0.5)) grabs it at once.
    far_from_hand = np.hypot(table["x"], table["y"] - 0.5) > 0.15
    expected = table["distance"] * np.sqrt(np.sum(GOAL_TIMES**2))
    np.testing.assert_allclose(table["error"][far_from_hand], expected[far_from_hand], atol=1e-6)
    # Rings hold their toys.
    for ring, (low, high) in enumerate(room.config.toy_rings, start=1):
        d = table[table["ring"] == ring]["distance"]
        assert d.min() >= low and d.max() <= high


def test_random_reference_is_seeded_and_normalisation_is_0_to_1():
    room = Playroom("kinematic", seed=0, config=PROJECT)
    settings = EvaluationSettings(n_placements=3, seed=4)
    a = competence_table(RestingAgent(), room, settings)
    b = competence_table(RestingAgent(), Playroom("kinematic", seed=0, config=PROJECT), settings)
    pd.testing.assert_frame_equal(a, b)
    # The reference is a random agent's own error: random commands that reach a toy score
    # otherwise than the resting agent, and another seed draws other commands.
    assert np.isfinite(a["random_error"]).all()
    assert (a["random_error"] != a["error"]).any()
    c = competence_table(RestingAgent(), room, EvaluationSettings(n_placements=3, seed=5))
    assert not np.allclose(a["random_error"], c["random_error"])
    same = pd.DataFrame({"error": [1.0, 2.0], "random_error": [1.0, 2.0]})
    perfect = pd.DataFrame({"error": [0.0, 0.0], "random_error": [1.0, 2.0]})
    assert normalised_competence(same) == 0.0 and normalised_competence(perfect) == 1.0


def test_eval_of_a_trial_writes_its_files_and_leaves_the_trial_unchanged(
    tmp_path, capsys, trained_trial
):
    trial = tmp_path / "t"
    shutil.copytree(trained_trial.dir, trial)  # evaluation writes beside the trial
    checkpoint = (trial / "checkpoint.npz").read_bytes()
    summary = evaluate_trial(trial, EvaluationSettings(n_placements=2))
    assert summary["evaluated_at_iteration"] == 3000
    assert set(summary["competence"]) == {"all", "ring1", "ring2", "ring3"}
    assert len(summary["vocal"]["best_distance"]) == 6 and len(summary["vocal"]["names"]) == 3
    for name in ("eval.json", "competence.parquet", "vocal.parquet"):
        assert (trial / name).exists()
    # Each name row says which toy it names, in the room's order of names.
    vocal = pd.read_parquet(trial / "vocal.parquet")
    names = load_trial(trial)[2].words.names
    named = vocal[vocal["toy"] > 0].sort_values("toy")
    assert tuple(named["word"]) == names and (vocal["toy"] > 0).equals(vocal["is_name"])
    assert (trial / "checkpoint.npz").read_bytes() == checkpoint
    assert main(["eval", str(trial), "--placements", "2", "--quiet"]) == 0
    out = capsys.readouterr().out
    # Competence in %, as the report pages print it, not as a fraction.
    assert "normalised competence (0% = random agent, 100% = perfect)" in out
    assert re.search(r"all -?\d+\.\d%", out), out
    assert main(["eval", str(tmp_path / "nothing")]) == 2
    assert len(capsys.readouterr().err.strip().splitlines()) == 1
