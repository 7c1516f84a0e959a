"""The worlds a trial's final agent can be tested in besides its own.

A comparison of backends mixes what agents learned with the world they are tested in, as long
as every agent is tested in the world it learned in. An eval world is a grasp backend and the
world switches that make it, declared once here; `playroom eval DIR --world NAME` and a batch's
`eval_worlds` test the trial's final agent there (experiments/measure/trial_evaluation.py), and
experiments/analysis/eval_world_results.py reads a batch's evaluations in one world back.

What an eval world changes, and what it keeps:
- it keeps everything the trial learned with that is not the grasp: the voice, the DMP, the
  learner (the agent is the trial's checkpoint), the arm, the objects, the rings, the
  caregiver, the experimenter's rule, and the placements (drawn from the same seeds);
- it sets the backend to its `grasp`, and every backend switch (SWITCHES: the world settings
  one backend reads and the other does not) to the value the trial's preset gives it, without
  the trial's overrides of it, then its own `settings` on top. So `kinematic` is the kinematic
  backend with the catch rule of the trial's preset (the study preset: the study's rule), and
  `physical` the physical backend with objects pushed and no settling, whatever ablation the
  trial learned in. A rung of the contact ladder (a batch config that sets world switches) is
  one more entry of EVAL_WORLDS with those switches in its `settings`.

A trial is never evaluated twice in one world: an eval world equal to the trial's own (same
backend, and every switch that backend reads equal: `own_world`) is its own evaluation,
eval.json in the trial directory, which `playroom eval DIR` writes; the other worlds' are
written beside it, in `eval-in-NAME/` (layout.eval_world_dir).

Plain functions of config.json's dicts and the world's settings dataclass: readers of results
use them without a room.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping
from types import MappingProxyType
from typing import Any

from sim.config import backend_switches, world_preset

# The trial's own world: its own evaluation (eval.json in the trial directory).
OWN = "own"

# The world settings that only some grasp backends read, by backend: declared once, beside each
# field (sim/config.py ACTS_ON). tests/measure/test_eval_worlds.py checks that a backend's
# movements do not change with a switch it is not listed with.
READ_BY: Mapping[str, tuple[str, ...]] = MappingProxyType(backend_switches())
SWITCHES: tuple[str, ...] = tuple(s for switches in READ_BY.values() for s in switches)


class EvalWorldError(ValueError):
    """A trial that cannot be tested in an eval world (one line: why)."""


@dataclasses.dataclass(frozen=True)
class EvalWorld:
    """A grasp backend, and the backend switches set on top of the trial preset's."""

    name: str
    grasp: str
    settings: Mapping[str, Any] = dataclasses.field(default_factory=dict)
    meaning: str = ""

    def __post_init__(self) -> None:
        # Anything else would test the agent in a world that differs from its own by more
        # than the grasp: a voice or DMP of another trial.
        others = sorted(set(self.settings) - set(SWITCHES))
        if others:
            raise ValueError(
                f"eval world {self.name!r} sets {others}: an eval world sets only the backend "
                f"switches {', '.join(SWITCHES)}"
            )
        if self.grasp not in READ_BY:
            raise ValueError(f"eval world {self.name!r}: unknown grasp {self.grasp!r}")
        object.__setattr__(self, "settings", MappingProxyType(dict(self.settings)))


EVAL_WORLDS: Mapping[str, EvalWorld] = MappingProxyType(
    {
        w.name: w
        for w in (
            EvalWorld(
                "kinematic",
                "kinematic",
                meaning="the study's distance rules, with the catch rule of the trial's preset",
            ),
            EvalWorld(
                "physical",
                "physical",
                meaning="MuJoCo contacts, objects pushed, no settling between movements",
            ),
        )
    }
)
# What `playroom eval --world` accepts.
WORLD_NAMES: tuple[str, ...] = (OWN, *EVAL_WORLDS)


def _preset(config: dict) -> str:
    try:
        return str(config["trial"]["preset"])
    except (KeyError, TypeError):
        raise EvalWorldError(
            "config.json names no preset: the switches of an eval world are the preset's"
        ) from None


def world_settings(config: dict, name: str) -> tuple[str, dict]:
    """(grasp, world settings as config.json holds them) of eval world `name` for the trial of
    `config` (its config.json, added settings filled in: experiments/trial_dir/config_file.py)."""
    if name not in EVAL_WORLDS:
        raise EvalWorldError(f"unknown eval world {name!r}: one of {', '.join(EVAL_WORLDS)}")
    world = EVAL_WORLDS[name]
    preset = world_preset(_preset(config))
    switches = {s: getattr(preset, s) for s in SWITCHES}
    return world.grasp, {**config["world"], **switches, **world.settings}


def own_world(config: dict, name: str) -> bool:
    """Whether eval world `name` is the trial's own: the same backend, and every switch that
    backend reads as the trial had it (a switch it does not read changes none of its
    movements)."""
    grasp, world = world_settings(config, name)
    if grasp != config["trial"]["grasp"]:
        return False
    return all(world[s] == config["world"][s] for s in READ_BY[grasp])


def world_record(config: dict, name: str) -> dict:
    """What eval.json records of the world a trial was tested in: its name, backend, every
    world setting, and how it differs from the trial's own (`setting`: [own, tested])."""
    grasp, world = world_settings(config, name)
    differs = {
        f"world.{k}": [config["world"][k], v] for k, v in world.items() if config["world"][k] != v
    }
    if grasp != config["trial"]["grasp"]:
        differs = {"trial.grasp": [config["trial"]["grasp"], grasp], **differs}
    return {
        "name": name,
        "grasp": grasp,
        "world": world,
        "differs_from_own": differs,
        # The scene learning left is a state of the trial's own world (docs/protocol.md D26).
        "study_tests_start": "the eval world's start scene, placed from the trial's seed",
    }
