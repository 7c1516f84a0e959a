"""The configs a trial's settings make (experiments/run/settings.py: `TrialSettings`), typed
once: its world, voice and learner configs, from which its room and agent are built, and the
same as config.json holds them (`full_config`). Every value is checked here, before a trial
writes anything (the configs check their own fields: sim/config.py, sim/vocal/config.py,
learner/config.py)."""

from __future__ import annotations

import dataclasses
import json
from importlib.metadata import version
from typing import NamedTuple

from experiments.run.settings import TrialSettings
from experiments.trial_dir.config_file import WORLD_CHOICES
from experiments.trial_dir.errors import TrialError
from learner.config import LearnerConfig, learner_preset
from sim.config import WorldConfig, inert_settings, world_preset
from sim.physics import PlayroomPhysics
from sim.vocal.config import DEFAULT_VOICE, VoiceConfig
from sim.vocal.diva.data import DivaDataError, DivaDataMissing, installed_fit


class TypedConfig(NamedTuple):
    """A trial's settings typed once: its world, voice and learner configs, from which its room
    and agent are built (`trial_parts.trial_parts`), and `json`, the same as config.json holds
    them."""

    world: WorldConfig
    voice: VoiceConfig
    learner: LearnerConfig
    json: dict


def full_config(
    settings: TrialSettings,
    world: WorldConfig | None = None,
    voice: VoiceConfig = DEFAULT_VOICE,
    learner: LearnerConfig | None = None,
) -> dict:
    """Every setting of a trial, as written to config.json: what `fresh_trial_parts` builds
    the trial's room and agent from. Every value is checked here, before a trial writes
    anything: TrialError (one line) naming the setting and what it allows."""
    return typed_config(settings, world, voice, learner).json


def typed_config(
    settings: TrialSettings,
    world: WorldConfig | None = None,
    voice: VoiceConfig = DEFAULT_VOICE,
    learner: LearnerConfig | None = None,
) -> TypedConfig:
    """`full_config`, with the typed configs it was made from (a run builds its room and agent
    from these, without reading its own JSON back)."""
    changes = settings.overrides
    try:
        learner = learner or learner_preset(
            settings.preset, **{"babbling": settings.babbling, **changes.get("learner", {})}
        )
        world = world or world_preset(
            settings.preset,
            **{
                **{name: getattr(settings, name) for name in WORLD_CHOICES},
                **changes.get("world", {}),
            },
        )
        # A world switch no rule of the trial's backend reads would only be recorded: refused
        # (a TrialError, which the clause below lets through).
        inert = inert_settings(settings.grasp, changes.get("world", {}))
        if inert:
            raise TrialError(
                f"overrides.world.{inert[0]} changes nothing on the {settings.grasp} backend "
                "(none of its rules reads it: sim/config.py); leave it out, or run it on a "
                "backend it acts on (a batch of several backends: one batch per backend)"
            )
        # The MJCF's lengths must equal the world's (sim/physics.py): refused now rather than
        # when the room is built, after config.json is written. A load costs milliseconds.
        PlayroomPhysics.load(world)
    except (TypeError, ValueError) as exc:  # an unknown field, or a value out of range
        raise TrialError(f"overrides do not fit the configs: {exc}") from None
    if world.voice == "diva":
        # Its data is the user's: checked before anything is written, never replaced by VTL.
        try:
            installed_fit()
        except (DivaDataMissing, DivaDataError) as exc:
            raise TrialError(str(exc)) from None
    config = {
        "trial": dataclasses.asdict(settings),
        "world": dataclasses.asdict(world),
        "voice": dataclasses.asdict(voice),
        "learner": learner.to_dict(),
        "package_version": version("playroom"),
    }
    # Through JSON and back, so that it compares equal to what config.json holds; strict JSON
    # (no NaN or Infinity), as storage.write_json writes it.
    as_json = json.loads(json.dumps(config, allow_nan=False))
    return TypedConfig(world, voice, learner, as_json)
