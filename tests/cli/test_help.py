"""The command line as people expect it: help on every option with its default and choices,
`--version`, argparse's usage line in its own errors (the commands' own errors stay one line),
and `--set SECTION.NAME=VALUE` checked as the configs check overrides."""

from __future__ import annotations

import argparse
import json
import re

import pytest

from experiments.cli.main import build_parser, main
from experiments.cli.overrides import dotted_setting, merged
from sim.grasping.names import GRASPS


def _subparsers(parser: argparse.ArgumentParser) -> dict[str, argparse.ArgumentParser]:
    actions = [a for a in parser._actions if isinstance(a, argparse._SubParsersAction)]
    return dict(actions[0].choices)


def test_every_option_of_every_command_has_help():
    parser = build_parser()
    missing = [
        f"{name} {action.dest}"
        for name, sub in _subparsers(parser).items()
        for action in sub._actions
        if not action.help
    ]
    assert missing == []


@pytest.mark.parametrize(
    "command, shown",
    [
        ("run", ["default: 80000", "default: kinematic", "{" + ",".join(GRASPS) + "}", "--set"]),
        ("random", ["(default: 20)", "(default: kinematic)", "(default: 0)"]),
        ("render", ["(default: 640x480)", "(default: 50.0)", "(default: top)"]),
        ("eval", ["(default: 100)", "{own," + ",".join(GRASPS) + "}", "(default: own)"]),
        ("batch", ["smoke", "paper", "dashboard", "--set"]),
        ("bench", ["trial, learner, world, tracking, voice, render, emulated"]),
        ("say", ["{oey,uye,iuo,eyu,eou,yeo}"]),
        ("report", ["study_reference_commands"]),
    ],
)
def test_help_shows_defaults_and_choices(capsys, command, shown):
    assert main([command, "--help"]) == 0
    text = " ".join(capsys.readouterr().out.split())  # argparse wraps lines
    for piece in shown:
        assert piece in text, (piece, text)
    assert "default: None" not in text and "default: False" not in text


def test_version_names_the_package_and_its_commit(capsys):
    assert main(["--version"]) == 0
    line = capsys.readouterr().out.strip()
    assert re.fullmatch(
        r"playroom \d+\.\d+\.\d+\S* \((commit [0-9a-f]{7}(\+dirty)?|installed package|unknown.*)\)",
        line,
    ), line


def test_argparse_errors_keep_the_usage_line(capsys):
    assert main(["run", "--out", "x", "--grasp", "magnetic"]) == 2
    lines = capsys.readouterr().err.strip().splitlines()
    assert lines[0].startswith("usage: playroom run ")
    assert lines[-1].startswith("playroom run: error: argument --grasp: invalid choice")


def test_a_commands_own_errors_stay_one_line(tmp_path, capsys):
    assert main(["run", "--out", str(tmp_path / "none"), "--resume"]) == 2
    err = capsys.readouterr().err
    assert err.startswith("playroom run: error: no trial to resume") and err.count("\n") == 1


@pytest.mark.parametrize(
    "text, parsed",
    [
        ("learner.exploration_sigma=0.05", ("learner", "exploration_sigma", 0.05)),
        ("learner.clip_sensory=false", ("learner", "clip_sensory", False)),
        ("world.catch_rule=held_stick", ("world", "catch_rule", "held_stick")),
        ('world.catch_rule="study"', ("world", "catch_rule", "study")),
        ("learner.outcomes_to_infer=2", ("learner", "outcomes_to_infer", 2)),
    ],
)
def test_a_dotted_setting_is_json_when_it_parses_else_a_string(text, parsed):
    assert dotted_setting(text) == parsed


@pytest.mark.parametrize(
    "text, said",
    [
        ("exploration_sigma=0.05", "expected SECTION.NAME=VALUE"),
        ("learner.exploration_sigma", "expected SECTION.NAME=VALUE"),
        ("learner.=1", "expected SECTION.NAME=VALUE"),
        ("voice.x=1", "unknown section 'voice'"),
    ],
)
def test_a_bad_dotted_setting_is_refused(text, said):
    with pytest.raises(argparse.ArgumentTypeError, match=re.escape(said)):
        dotted_setting(text)


def test_a_set_wins_over_the_config_and_a_setting_set_twice_is_refused():
    base = {"learner": {"exploration_sigma": 0.1}}
    assert merged(base, [("learner", "exploration_sigma", 0.2)]) == {
        "learner": {"exploration_sigma": 0.2}
    }
    assert base == {"learner": {"exploration_sigma": 0.1}}
    sets = [("learner", "exploration_sigma", 0.2), ("learner", "exploration_sigma", 0.3)]
    with pytest.raises(ValueError, match="exploration_sigma is given twice"):
        merged(base, sets)


def test_a_setting_set_twice_on_the_command_line_is_one_line_and_writes_nothing(tmp_path, capsys):
    out = tmp_path / "trial"
    twice = ["--set", "learner.exploration_sigma=0.05", "--set", "learner.exploration_sigma=0.1"]
    assert main(["run", "--out", str(out), "--iterations", "3", "--quiet", *twice]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "given twice" in err[0] and not out.exists()
    batch = ["batch", "--profile", "smoke", "--out", str(tmp_path / "b"), "--quiet", *twice]
    assert main(batch) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "given twice" in err[0] and not (tmp_path / "b").exists()


@pytest.mark.parametrize(
    "setting",
    [
        "world.push_objects=false",
        "world.settle_between_movements=true",
        "world.held_pose=aligned",
    ],
)
def test_a_world_switch_the_backend_never_reads_is_refused(tmp_path, capsys, setting):
    out = tmp_path / "trial"
    assert main(["run", "--out", str(out), "--iterations", "3", "--quiet", "--set", setting]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "changes nothing on the kinematic backend" in err[0]
    assert not out.exists()
    physical = ["run", "--out", str(out), "--iterations", "3", "--quiet", "--grasp", "physical"]
    assert main([*physical, "--set", setting]) == 0  # where it acts it is taken
    capsys.readouterr()
    batch = ["batch", "--profile", "smoke", "--out", str(tmp_path / "b"), "--set", setting]
    assert main([*batch, "--quiet"]) == 2  # the smoke batch holds kinematic trials too
    assert "one batch per backend" in capsys.readouterr().err


def test_run_set_reaches_the_trials_config_and_is_checked(tmp_path, capsys):
    out = tmp_path / "trial"
    run = ["run", "--out", str(out), "--iterations", "3", "--quiet"]
    assert main([*run, "--set", "learner.exploration_sigma=-1"]) == 2
    err = capsys.readouterr().err
    assert "exploration_sigma" in err and err.count("\n") == 1 and not out.exists()
    assert main([*run, "--set", "learner.no_such=1"]) == 2
    assert "unknown settings no_such" in capsys.readouterr().err
    assert main([*run, "--set", "learner.exploration_sigma=0.07"]) == 0
    config = json.loads((out / "config.json").read_text())
    assert config["learner"]["exploration_sigma"] == 0.07
    assert config["trial"]["overrides"] == {"learner": {"exploration_sigma": 0.07}}
    # A resume given other overrides is refused; given the same, it goes on.
    resume = ["run", "--out", str(out), "--iterations", "5", "--resume", "--quiet"]
    assert main([*resume, "--set", "learner.exploration_sigma=0.05"]) == 2
    assert "--set" in capsys.readouterr().err
    assert main([*resume, "--set", "learner.exploration_sigma=0.07"]) == 0


def test_the_bench_sections_the_help_lists_are_those_measured():
    from experiments.bench.names import SECTION_NAMES
    from experiments.bench.sections import SECTIONS

    assert tuple(SECTIONS) == SECTION_NAMES
