"""`playroom random`: random arm commands in a room of a preset, with world settings changed
(a rung of the contact ladder, docs/world.md), and the share of commands that grasp or catch."""

from __future__ import annotations

import pytest

from experiments.cli.main import main


def _shares(out: str) -> str:
    return next(line for line in out.splitlines() if "share of commands" in line)


def test_random_takes_a_preset_and_world_settings(capsys):
    base = ["random", "--iterations", "100", "--seed", "3", "--preset", "study"]
    assert main(base) == 0
    set_arm = capsys.readouterr().out
    assert main([*base, "--set", "world.arm_dynamics=servo"]) == 0
    servo_arm = capsys.readouterr().out
    assert "stick_grasped" in _shares(set_arm) and "toy_caught" in _shares(set_arm)
    # The servo arm lags its targets: some grasps come a step later, or not at all.
    assert servo_arm != set_arm


@pytest.mark.parametrize(
    "setting, said",
    [
        ("world.held_pose=aligned", "changes nothing on the kinematic backend"),
        ("learner.exploration_sigma=0.1", "world settings only"),
        ("world.arm_dynamics=fast", "arm_dynamics"),
        ("world.no_such=1", "no_such"),
    ],
)
def test_random_refuses_a_setting_it_cannot_take_in_one_line(capsys, setting, said):
    assert main(["random", "--iterations", "1", "--set", setting]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and said in err[0], err
