"""The positive control's settings as a user gives them (`playroom rl-control`): the tests fall
every `eval_every` movements and at the end, the learner's hyperparameters reach
stable-baselines3 where it reads them, and bad settings are refused in one line before anything
runs. No RL library needed."""

from __future__ import annotations

import pytest

from experiments.baseline.control_settings import (
    HYPERPARAMETERS,
    ControlError,
    ControlSettings,
    learner_values,
    sac_arguments,
)
from experiments.cli.main import main


def test_the_learner_is_tested_before_it_moves_and_every_eval_every_movements():
    settings = ControlSettings("stick", seed=2, movements=6000, eval_every=2000)
    assert settings.checkpoints() == [0, 2000, 4000, 6000]
    assert settings.name == "stick-seed0002" and settings.learner == "sac-her"


def test_validation_goals_are_never_the_held_out_ones():
    held_out = ControlSettings("hand", eval_goals=200).test_seeds()
    validation = ControlSettings("hand", eval_goals=200, test_goals="validation").test_seeds()
    assert len(held_out) == len(validation) == 200 and not set(held_out) & set(validation)
    assert ControlSettings("hand", settings="defaults").learner == "sac-her-defaults"


def test_each_hyperparameter_reaches_the_argument_stable_baselines3_reads():
    arguments = sac_arguments()
    assert arguments["replay_buffer_kwargs"] == {
        "n_sampled_goal": 4,
        "goal_selection_strategy": "future",
    }
    assert arguments["policy_kwargs"] == {"net_arch": [64, 64]}
    assert arguments["learning_rate"] == learner_values()["learning_rate"]
    flat = {k for k in arguments if not k.endswith("_kwargs")}
    assert flat | {"n_sampled_goal", "goal_selection_strategy", "net_arch"} == set(HYPERPARAMETERS)
    assert all(why for _, why in HYPERPARAMETERS.values())  # each one says why
    assert sac_arguments("defaults") == {}  # stable-baselines3's own, every one


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"goal": "toy1"}, "^unknown goal 'toy1': one of hand, stick$"),
        ({"goal": "hand", "grasp": "magnetic"}, "^unknown grasp 'magnetic'"),
        ({"goal": "hand", "settings": "tuned"}, "^unknown settings 'tuned': one of control, de"),
        ({"goal": "hand", "test_goals": "train"}, "^unknown test_goals 'train': one of held-out"),
        ({"goal": "hand", "seed": -1}, "^seed must be an integer >= 0, got -1$"),
        ({"goal": "hand", "movements": 1000, "eval_every": 300}, "multiple of eval_every"),
        ({"goal": "hand", "eval_goals": 0}, "^eval_goals must be an integer >= 1"),
    ],
)
def test_bad_settings_are_refused_in_one_line(kwargs, message):
    with pytest.raises(ControlError, match=message) as caught:
        ControlSettings(**kwargs)
    assert "\n" not in str(caught.value)


def test_the_command_refuses_them_before_anything_is_written(tmp_path, capsys):
    out = tmp_path / "control"
    code = main(["rl-control", "--out", str(out), "--movements", "1000", "--every", "300"])
    assert code == 2
    (line,) = capsys.readouterr().err.strip().splitlines()
    assert line.startswith("playroom rl-control: error:") and "multiple of eval_every" in line
    assert not out.exists()
