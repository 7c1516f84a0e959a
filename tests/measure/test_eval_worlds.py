"""A trial's final agent tested in another world than its own: `playroom eval DIR
--world NAME` writes beside the trial, never into its files; an eval world equal to the trial's
own is its own evaluation; an eval world changes only the backend and its switches, each
switch read by the backend it is listed with."""

from __future__ import annotations

import dataclasses
import hashlib
import shutil
import subprocess
import sys

import numpy as np
import pytest

from experiments.cli.main import main
from experiments.run.settings import TrialSettings
from experiments.run.trial import run_trial
from experiments.run.trial_config import full_config
from experiments.trial_dir import eval_worlds, storage
from experiments.trial_dir.eval_worlds import (
    EVAL_WORLDS,
    READ_BY,
    SWITCHES,
    EvalWorld,
    own_world,
    world_record,
    world_settings,
)
from experiments.trial_dir.layout import (
    COMPETENCE_FILE,
    EVAL_FILE,
    EVALUATION_TABLES,
    LOCK_FILE,
    STALE_PREFIX,
    eval_world_dir,
)
from models.layout import ARM_DIM
from sim import Playroom
from sim.config import world_preset
from sim.grasping.names import GRASPS

KINEMATIC = TrialSettings(grasp="kinematic", iterations=300, seed=0, checkpoint_every=300)
PHYSICAL = TrialSettings(grasp="physical", iterations=100, seed=0, checkpoint_every=100)


@pytest.fixture(scope="module")
def trials(tmp_path_factory):
    root = tmp_path_factory.mktemp("eval-worlds")
    out = {}
    for settings in (KINEMATIC, PHYSICAL):
        out[settings.grasp] = root / settings.grasp
        run_trial(out[settings.grasp], settings, progress=False)
    return out


def _copy(trial, tmp_path):
    return shutil.copytree(trial, tmp_path / trial.name)


def _files(trial) -> dict[str, bytes]:
    """Every file of a trial directory but its eval worlds' folders and the lock, whose content
    is its current writer's process id, by path."""
    return {
        p.relative_to(trial).as_posix(): p.read_bytes()
        for p in sorted(trial.rglob("*"))
        if p.is_file()
        and p.name != LOCK_FILE
        and not p.relative_to(trial).parts[0].startswith("eval-in-")
    }


def _eval(trial, capsys, *extra: str) -> tuple[int, str, list[str]]:
    code = main(["eval", str(trial), "--quiet", "--placements", "1", *extra])
    captured = capsys.readouterr()
    return code, captured.out, captured.err.strip().splitlines()


def test_an_eval_in_another_world_writes_its_folder_and_leaves_the_trial_as_it_was(
    trials, tmp_path, capsys
):
    trial = _copy(trials["kinematic"], tmp_path)
    assert _eval(trial, capsys)[0] == 0  # the trial's own evaluation first: it must stay
    before = _files(trial)
    code, out, err = _eval(trial, capsys, "--world", "physical")
    assert code == 0, err
    assert "tested in the physical world (grasp kinematic -> physical)" in out
    assert _files(trial) == before  # every byte of the trial's own files, its eval.json too
    folder = trial / eval_world_dir("physical")
    assert sorted(p.name for p in folder.iterdir()) == sorted((EVAL_FILE, *EVALUATION_TABLES))
    summary = storage.read_json(folder / EVAL_FILE)
    assert summary["grasp"] == "kinematic"  # what the agent learned in
    tested = summary["eval_world"]
    assert (tested["name"], tested["grasp"]) == ("physical", "physical")
    assert tested["differs_from_own"] == {"trial.grasp": ["kinematic", "physical"]}
    config = storage.read_json(trial / "config.json")
    assert tested["world"] == config["world"]  # the study preset's switches: its own world's
    assert summary["evaluated_at_iteration"] == KINEMATIC.iterations
    # eval.json lists its tables exactly as the trial's own evaluation does.
    for name in EVALUATION_TABLES:
        data = (folder / name).read_bytes()
        assert summary["files"][name] == [len(data), hashlib.sha256(data).hexdigest()]
    own = storage.read_json(trial / EVAL_FILE)
    assert "eval_world" not in own and summary["competence"] != own["competence"]


def test_a_cross_evaluation_removes_the_litter_of_a_killed_one(trials, tmp_path, capsys):
    trial = _copy(trials["kinematic"], tmp_path)
    folder = trial / eval_world_dir("physical")
    folder.mkdir()
    dead = subprocess.Popen([sys.executable, "-c", "pass"])
    dead.wait()
    litter = folder / f".{COMPETENCE_FILE}.{dead.pid}.tmp"
    litter.write_bytes(b"half a table")
    code, _, err = _eval(trial, capsys, "--world", "physical")
    assert code == 0 and not litter.exists()
    assert any("temporary file" in line for line in err), err


def test_the_trials_own_world_named_is_its_own_evaluation(trials, tmp_path, capsys):
    trial = _copy(trials["physical"], tmp_path)
    code, out, err = _eval(trial, capsys, "--world", "physical")
    assert code == 0 and len(err) == 1 and "its own" in err[0], err
    assert not (trial / eval_world_dir("physical")).exists()
    assert "tested in" not in out
    summary = storage.read_json(trial / EVAL_FILE)
    assert "eval_world" not in summary
    code, _, _ = _eval(trial, capsys)  # `playroom eval DIR`: the very same evaluation
    assert code == 0 and storage.read_json(trial / EVAL_FILE)["competence"] == summary["competence"]


def test_extending_a_trial_moves_its_eval_worlds_aside_with_its_other_derived_files(
    trials, tmp_path, capsys
):
    trial = _copy(trials["kinematic"], tmp_path)
    assert _eval(trial, capsys, "--world", "physical")[0] == 0
    longer = dataclasses.replace(KINEMATIC, iterations=KINEMATIC.iterations + 100)
    run_trial(trial, longer, resume=True, progress=False)
    assert not (trial / eval_world_dir("physical")).exists()
    stale = trial / f"{STALE_PREFIX}{KINEMATIC.iterations:08d}" / eval_world_dir("physical")
    assert (stale / EVAL_FILE).is_file()


def _config(**settings) -> dict:
    return full_config(TrialSettings(**settings))


def test_an_eval_world_keeps_the_trials_world_but_the_backend_and_the_presets_switches():
    # An ablation's agents are tested in the ordinary room of the backend.
    no_push = _config(grasp="physical", overrides={"world": {"push_objects": False}})
    assert not own_world(no_push, "physical")
    assert world_record(no_push, "physical")["differs_from_own"] == {
        "world.push_objects": [False, True]
    }
    # The kinematic world of a study-preset trial has the study's catch rule, of a project
    # one the project's; everything else (the DMP above all) stays the trial's.
    for preset in ("study", "project"):
        config = _config(grasp="physical", preset=preset)
        grasp, world = world_settings(config, "kinematic")
        assert grasp == "kinematic" and world["catch_rule"] == world_preset(preset).catch_rule
        assert {k: v for k, v in world.items() if k not in SWITCHES} == {
            k: v for k, v in config["world"].items() if k not in SWITCHES
        }
    held = _config(grasp="kinematic", overrides={"world": {"catch_rule": "held_stick"}})
    assert not own_world(held, "kinematic") and own_world(_config(grasp="kinematic"), "kinematic")
    # A switch the backend does not read leaves its world its own (no override can set one
    # now; a config.json may still hold one, written before that refusal).
    unread = _config(grasp="physical")
    unread["world"]["catch_rule"] = "held_stick"
    assert own_world(unread, "physical")


def test_an_eval_world_sets_backend_switches_only_and_a_rung_is_one_more_entry(monkeypatch):
    assert set(EVAL_WORLDS) <= set(GRASPS) and set(READ_BY) == set(GRASPS)
    with pytest.raises(ValueError, match="sets only the backend switches"):
        EvalWorld("other-dmp", "physical", {"dmp": "project"})
    rung = EvalWorld("physical-settled", "physical", {"settle_between_movements": True})
    monkeypatch.setattr(eval_worlds, "EVAL_WORLDS", {**EVAL_WORLDS, rung.name: rung})
    settled = _config(grasp="physical", overrides={"world": {"settle_between_movements": True}})
    assert own_world(settled, rung.name) and not own_world(settled, "physical")
    assert world_record(_config(grasp="kinematic"), rung.name)["differs_from_own"] == {
        "trial.grasp": ["kinematic", "physical"],
        "world.settle_between_movements": [False, True],
    }


@pytest.mark.parametrize("grasp", GRASPS)
def test_a_backend_moves_alike_whatever_the_switches_it_is_not_listed_with(grasp):
    """What `own_world` rests on: a switch of SWITCHES that READ_BY does not list with a
    backend changes none of its movements."""
    commands = np.random.default_rng(7).uniform(-1, 1, (25, ARM_DIM))
    base = world_preset("study")
    flipped = {
        "catch_distance": 0.055,
        "catch_rule": "held_stick",
        "arm_dynamics": "servo",
        "placements_clear": True,
        "stick_return_reach": None,
        "push_objects": False,
        "settle_between_movements": True,
        "held_pose": "aligned",
        "unheld_contacts": "sensed",
        "caregiver_carrying": "placed",
    }
    assert set(flipped) == set(SWITCHES)
    unread = {s: v for s, v in flipped.items() if s not in READ_BY[grasp]}
    voice = np.random.default_rng(8).uniform(-1, 1, (25, 28))
    outcomes = []
    for world in (base, dataclasses.replace(base, **unread)):
        room = Playroom(grasp, seed=5, config=world)
        outcomes.append(
            [
                room.act(s, m).s
                for a, v in zip(commands, voice, strict=True)
                for s, m in (("arm", a), ("voice", v))
            ]
        )
    assert np.array_equal(np.array(outcomes[0]), np.array(outcomes[1]))


def test_the_protocol_names_every_switch_an_eval_world_resets():
    """docs/protocol.md D26 lists the switches an eval world sets to the trial preset's
    values: every one of them (it once left out arm_dynamics and held_pose)."""
    from pathlib import Path

    text = (Path(__file__).resolve().parents[2] / "docs" / "protocol.md").read_text()
    d26 = text.split("**D26.")[1].split("**D27.")[0]
    config = full_config(TrialSettings(grasp="kinematic", iterations=10, seed=0))
    _, world = eval_worlds.world_settings(config, "physical")
    preset = world_preset("study")
    for switch in eval_worlds.SWITCHES:
        assert f"`{switch}`" in d26, switch
        assert world[switch] == getattr(preset, switch)
