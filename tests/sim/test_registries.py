"""The grasp backends and vocal tracts come from their registries, and every entry point takes
one default backend and one default preset (models/presets.py, sim/grasping/names.py). What
every registered backend must do: tests/sim/test_backend_contract.py."""

from __future__ import annotations

import argparse
import dataclasses

import numpy as np
import pytest

from experiments.batches.spec import BatchSpec
from experiments.cli.args import RUN_DEFAULTS
from experiments.cli.main import build_parser
from experiments.run.settings import TrialSettings
from experiments.trial_dir.errors import TrialError
from learner.agent import Agent
from learner.config import BABBLING_MODES, learner_preset
from models.presets import DEFAULT_PRESET, PRESETS
from models.tracts import DEFAULT_TRACT
from sim import Playroom
from sim.config import DEFAULT_WORLD, STICK_RETURNS, world_preset
from sim.grasping import registry
from sim.grasping.names import DEFAULT_GRASP, GRASPS
from sim.vocal.config import DEFAULT_VOICE
from sim.vocal.registry import load, make_tract
from sim.vocal.voice import Voice


def test_an_unknown_backend_or_tract_is_refused_naming_the_choices():
    with pytest.raises(ValueError, match="'kinematic', 'physical'"):
        registry.load("magnetic")
    with pytest.raises(ValueError, match="'vtl'"):
        make_tract("diva?", exact=False, config=DEFAULT_VOICE, world=DEFAULT_WORLD)


def test_the_room_takes_its_voice_from_the_tract_registry():
    room = Playroom(seed=0)
    assert isinstance(room.vocal_tract, Voice)
    assert type(room.vocal_tract) is load(DEFAULT_TRACT)
    assert room.vocal_tract.name == DEFAULT_TRACT
    assert room.vocal_tract.world == room.config


def test_room_agent_trial_and_batch_share_one_default_backend_and_preset():
    room = Playroom()
    assert room.grasp == DEFAULT_GRASP == "kinematic"
    assert DEFAULT_PRESET == "study"
    assert room.config == world_preset(DEFAULT_PRESET)
    assert Agent().config == learner_preset(DEFAULT_PRESET)
    trial = TrialSettings()
    assert (trial.grasp, trial.preset) == (DEFAULT_GRASP, DEFAULT_PRESET)
    assert (RUN_DEFAULTS["grasp"], RUN_DEFAULTS["preset"]) == (DEFAULT_GRASP, DEFAULT_PRESET)
    assert BatchSpec().preset == DEFAULT_PRESET
    # A run's other defaults are those of its world and learner.
    assert RUN_DEFAULTS["stick_return"] == room.config.stick_return
    assert RUN_DEFAULTS["babbling"] == Agent().config.babbling


def _options(command: str) -> dict[str, argparse.Action]:
    """The options of a `playroom` subcommand by destination."""
    parser = build_parser()
    sub = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    return {action.dest: action for action in sub.choices[command]._actions}


@pytest.mark.parametrize("command", ["random", "run", "render"])
def test_the_command_line_offers_the_registered_backends(command):
    grasp = _options(command)["grasp"]
    assert tuple(grasp.choices) == GRASPS
    # `run` leaves settings out (a resumed trial keeps its own); the others default.
    assert grasp.default == (None if command == "run" else DEFAULT_GRASP)


def test_the_command_line_offers_each_settings_declared_values():
    run = _options("run")
    assert tuple(run["preset"].choices) == PRESETS
    assert tuple(run["babbling"].choices) == BABBLING_MODES
    assert tuple(run["stick_return"].choices) == STICK_RETURNS


def test_a_trial_refuses_a_backend_the_registry_does_not_know():
    with pytest.raises(TrialError, match="kinematic, physical"):
        dataclasses.replace(TrialSettings(), grasp="magnetic")


def test_a_third_backend_is_its_module_and_one_registry_line(monkeypatch, tmp_path):
    """Registered by one line (tests/third_backend.py is its module), a backend runs a trial,
    which records what it declares; the estimate and the room's paths need nothing else."""
    from experiments.run import estimate
    from experiments.run.trial import run_trial
    from experiments.trial_dir import backend_record, storage
    from sim.grasping.registry import REGISTRY

    monkeypatch.setitem(REGISTRY, "long_reach", "third_backend:LongReachGrasp")
    settings = TrialSettings(grasp="long_reach", iterations=300, checkpoint_every=100)
    trial = run_trial(tmp_path / "trial", settings, progress=False)
    assert trial.iteration == 300
    config = storage.read_json(tmp_path / "trial" / "config.json")
    record = backend_record.read_record(tmp_path / "trial", config)
    assert record["grasp"] == "long_reach"
    assert record["reach"] == pytest.approx(trial.room.backend.reach())
    assert estimate.trial_costs(settings).seconds > 0
    # Its own rule: the hand takes what lies within twice the study's distance.
    assert trial.room.backend.config.grasp_distance == 2 * trial.room.config.grasp_distance


def test_the_playroom_builds_the_parts_a_backend_declares(monkeypatch):
    """A backend declaring another grasp rule (tests/third_backend.py) gets it from the room,
    which hands the caregiver the backend's carrying: the same random arm movements that grasp
    in the physical backend grasp nothing under a rule that takes nothing."""
    from third_backend import TakesNothing

    from sim import Playroom
    from sim import events as ev
    from sim.grasping.carrying import WeldedCarrying
    from sim.grasping.registry import REGISTRY

    monkeypatch.setitem(REGISTRY, "touchless", "third_backend:TouchlessGrasp")
    commands = np.random.default_rng(0).uniform(-1, 1, (20, 21))
    taken = {}
    for grasp in ("physical", "touchless"):
        room = Playroom(grasp, seed=3)
        assert room.caregiver.carrying is room.backend.carrying
        assert isinstance(room.backend.carrying, WeldedCarrying)
        kinds = [e.kind for m in commands for e in room.act("arm", m).events]
        taken[grasp] = sum(k in (ev.STICK_GRASPED, ev.TOY_GRASPED, ev.TOY_CAUGHT) for k in kinds)
    assert isinstance(room.backend.rule, TakesNothing)
    assert taken["physical"] > 0 and taken["touchless"] == 0
