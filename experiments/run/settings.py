"""What a user chooses for one trial, checked before anything is written.

`TrialSettings` are the choices of `playroom run` (and of each trial of a batch), each checked
on its own; the configs they make, every value checked, are experiments/run/trial_config.py's.
`resume_settings` gives the settings of `playroom run --resume`: the trial's own, read from its
config.json, which settings given on the command line must match.
"""

from __future__ import annotations

import dataclasses
import os
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from experiments.trial_dir.config_file import WORLD_CHOICES
from experiments.trial_dir.errors import TrialError
from experiments.trial_dir.reading import open_for_reading
from learner.config import BABBLING_MODES, LearnerConfig
from models.checks import INT64_MAX, check_seed
from models.presets import DEFAULT_PRESET, PRESETS
from models.tracts import DEFAULT_TRACT, TRACTS
from sim.config import STICK_RETURNS, WorldConfig
from sim.grasping.names import DEFAULT_GRASP
from sim.grasping.registry import REGISTRY

# Bounds of the trial's own settings. Iterations are logged as int64. A checkpoint period's rows
# are held in memory until its checkpoint writes them, about a kilobyte each: a million is a GB.
ITERATIONS_MAX = INT64_MAX
CHECKPOINT_EVERY_MAX = 1_000_000


@dataclass(frozen=True)
class TrialSettings:
    """What a user chooses for one trial (`playroom run`)."""

    grasp: str = DEFAULT_GRASP
    iterations: int = 1000
    seed: int = 0
    babbling: str = LearnerConfig.babbling  # the one default, beside the setting
    checkpoint_every: int = 1000
    stick_return: str = WorldConfig.stick_return  # the experimenter's rule (sim/experimenter.py)
    # "study": the world and learner as the study's code behaved; "project": this project's
    # earlier choices (sim.config.world_preset, learner.config.learner_preset).
    preset: str = DEFAULT_PRESET
    # The vocal tract (models/tracts.py): "vtl" (VocalTractLab) or "diva" (the study's DIVA
    # map, from the user's installed data: `playroom voice-data diva PATH`). It chooses the
    # world's `voice` (config_file.WORLD_CHOICES), whose field declares what trials written
    # before the choice ran with.
    voice: str = DEFAULT_TRACT
    # Single settings changed after the preset, {"world": {...}, "learner": {...}}: one
    # departure switched at a time (ablations, docs/replication.md).
    overrides: dict = dataclasses.field(default_factory=dict)

    def __post_init__(self) -> None:
        if self.grasp not in REGISTRY:  # the registry as it is now (a test may add to it)
            raise TrialError(f"unknown grasp {self.grasp!r}: one of {', '.join(REGISTRY)}")
        if self.preset not in PRESETS:
            raise TrialError(f"unknown preset {self.preset!r}: one of {', '.join(PRESETS)}")
        if self.voice not in TRACTS:
            raise TrialError(f"unknown voice {self.voice!r}: one of {', '.join(TRACTS)}")
        if self.babbling not in BABBLING_MODES:
            raise TrialError(
                f"unknown babbling {self.babbling!r}: one of {', '.join(BABBLING_MODES)}"
            )
        _check_overrides(self.overrides)
        if self.stick_return not in STICK_RETURNS:
            raise TrialError(
                f"unknown stick_return {self.stick_return!r}: one of {', '.join(STICK_RETURNS)}"
            )
        for name, maximum in (
            ("iterations", ITERATIONS_MAX),
            ("checkpoint_every", CHECKPOINT_EVERY_MAX),
        ):
            value = getattr(self, name)
            if isinstance(value, bool) or not isinstance(value, int) or value <= 0:
                raise TrialError(f"{name} must be a positive integer, got {value!r}")
            if value > maximum:
                shown = "2**63 - 1" if maximum == INT64_MAX else str(maximum)
                raise TrialError(f"{name} must be at most {shown}, got {value!r}")
        if isinstance(self.seed, bool) or not isinstance(self.seed, int) or self.seed < 0:
            raise TrialError(f"seed must be a non-negative integer, got {self.seed!r}")
        try:  # every log row holds the seed in an int64 column
            check_seed("seed", self.seed)
        except ValueError as exc:
            raise TrialError(str(exc)) from None


# Override sections, their configs, and the fields a trial setting owns: an override of one
# would make config.json's "trial" section say something else than the world or learner does.
OVERRIDABLE = {
    "world": (WorldConfig, WORLD_CHOICES),
    "learner": (LearnerConfig, ("babbling",)),
}


def _check_overrides(overrides: object) -> None:
    """The overrides' shape and names (their values are checked by the configs themselves)."""
    if not isinstance(overrides, dict):
        raise TrialError(
            f"overrides must be {{'world': {{...}}, 'learner': {{...}}}}, got {overrides!r}"
        )
    unknown = sorted(set(overrides) - set(OVERRIDABLE))
    if unknown:
        raise TrialError(f"overrides of unknown sections {unknown}: 'world' or 'learner'")
    for section, values in overrides.items():
        cls, owned = OVERRIDABLE[section]
        if not isinstance(values, dict):
            raise TrialError(f"overrides.{section} must be an object of settings, got {values!r}")
        known = {f.name for f in dataclasses.fields(cls)} - set(owned)
        unknown = sorted(set(values) - known)
        taken = sorted(set(owned) & set(values))
        if taken:
            raise TrialError(
                f"overrides.{section}.{taken[0]} is the trial setting {taken[0]}: set that instead"
            )
        if unknown:
            raise TrialError(
                f"overrides.{section}: unknown settings {', '.join(map(str, unknown))} "
                f"(known: {', '.join(sorted(known))})"
            )


def resume_settings(out_dir: str | os.PathLike, given: dict[str, Any]) -> TrialSettings:
    """The settings a resumed trial runs with (`playroom run --resume`): those stored in its
    config.json, overrides included. `given` holds the settings the user gave explicitly;
    each must match the stored one, except a larger `iterations`, which extends the trial.
    TrialError, one line: no trial to resume in `out_dir`, or every mismatch at once."""
    names = [f.name for f in dataclasses.fields(TrialSettings)]
    unknown = sorted(set(given) - set(names))
    if unknown:
        raise TrialError(f"unknown trial settings {unknown}: one of {', '.join(names)}")
    stored = stored_settings(out_dir)
    dataclasses.replace(stored, **given)  # each given value checked on its own first
    mismatches = []
    for name, value in given.items():
        have = getattr(stored, name)
        option = "--" + name.replace("_", "-")  # as `playroom run` names it
        if name == "overrides":
            option = "--set"
        if name == "iterations" and value < have:
            mismatches.append(f"{option} {value} (it has {have}; only a larger number extends it)")
        elif name != "iterations" and value != have:
            mismatches.append(f"{option} {value} (it has {have})")
    if mismatches:
        raise TrialError(
            f"{out_dir} holds a trial of another configuration: {'; '.join(mismatches)}; "
            "leave these settings out to resume it as it is"
        )
    return dataclasses.replace(stored, iterations=given.get("iterations", stored.iterations))


def stored_settings(out_dir: str | os.PathLike) -> TrialSettings:
    """The TrialSettings a trial directory's config.json holds; TrialError when there is none."""
    stored = open_for_reading(out_dir)
    path = stored.config_path
    if not Path(out_dir).is_dir():
        why = "not a directory" if Path(out_dir).exists() else "no such directory"
        raise TrialError(f"no trial to resume in {out_dir}: {why}")
    if not path.is_file():
        raise TrialError(f"no trial to resume in {out_dir}: it holds no {path.name}")
    config = stored.config_json()
    trial = config.get("trial") if isinstance(config, dict) else None
    if not isinstance(trial, dict):
        raise TrialError(f'{path} holds no trial settings (no "trial" section)')
    known = {f.name for f in dataclasses.fields(TrialSettings)}
    unknown = sorted(set(trial) - known)
    if unknown:
        raise TrialError(f"{path} holds unknown trial settings: {', '.join(unknown)}")
    return TrialSettings(**trial)
