"""The replay of remembered movements (experiments/measure/replay.py): its test scene
is the evaluation's own, and the remembered scenes are where the movement was learned."""

from __future__ import annotations

import numpy as np

from experiments.measure.evaluation import EvaluationSettings, competence_table
from experiments.measure.replay import SCENES, replay_table
from experiments.run.trial_parts import load_trial


def test_the_test_scene_is_the_evaluations_and_a_remembered_scene_brings_the_outcome_back(
    trained_trial,
):
    settings = EvaluationSettings(n_placements=6)
    _, agent, room, _ = load_trial(trained_trial.dir)
    state = room.get_state()
    table = replay_table(agent, room, settings)
    room.set_state(state)
    evaluated = competence_table(agent, room, settings)
    arm = evaluated[(evaluated["ring"] == 1) & (evaluated["strategy"] != "vocal")]
    arm = arm[~arm["untrained"]].set_index(["placement", "toy"])
    assert len(table) == len(arm) > 0
    # The same scenes and commands as the evaluation: the same errors, to the last bit.
    replayed = table.set_index(["placement", "toy"])["error_test"]
    np.testing.assert_array_equal(replayed.loc[arm.index].to_numpy(), arm["error"].to_numpy())
    np.testing.assert_array_equal(table["expected"].to_numpy(), arm["arm_nn_distance"].to_numpy())
    # The kinematic rules repeat a movement exactly where it was learned, other toys away.
    assert (table["repeat_alone"] < 1e-6).mean() >= 0.5
    assert all(table[f"repeat_{s}"].ge(0).all() for s in SCENES)
