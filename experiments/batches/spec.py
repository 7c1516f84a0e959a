"""What a batch holds (`BatchSpec`) and its JSON form (profiles, `--config` files): every
field checked where the spec is built, without coercion, so that a batch is refused with one
line naming the setting before anything is written or any cluster started."""

from __future__ import annotations

import dataclasses
import json
import os
from collections import Counter
from dataclasses import dataclass, field
from importlib import resources
from pathlib import Path
from typing import TypeGuard

from experiments.analysis.study_summary import RANDOM_COMMANDS_PER_RING
from experiments.batches.stored import stored_profiles
from experiments.run.settings import TrialSettings
from experiments.run.trial_config import full_config
from experiments.trial_dir import storage
from experiments.trial_dir.errors import TrialError
from experiments.trial_dir.eval_worlds import EVAL_WORLDS
from learner.config import BABBLING_MODES, LearnerConfig
from models.checks import MAX_SEED
from models.presets import DEFAULT_PRESET, PRESETS
from models.tracts import DEFAULT_TRACT, TRACTS
from sim.config import STICK_RETURNS, WorldConfig
from sim.grasping.names import GRASPS


class BatchError(Exception):
    """A batch that cannot run as asked; the message says why."""


# The most seeds a count ("seeds": N, seeds 0..N-1) may ask for: each seed is a trial directory
# and a Dask task the scheduler holds from the start (the paper's profile has 500 seeds per
# backend); a count far beyond this is a typo, and a count of 10**23 would be built as a tuple
# before anything else is checked. A list of seeds is as long as its file.
MAX_SEED_COUNT = 100_000


# Fields of a batch config and of `BatchSpec`, with what each may hold (for the messages).
FIELD_RULES = {
    "grasps": f"a non-empty list of distinct values from {', '.join(GRASPS)}",
    "babbling": f"a non-empty list of distinct values from {', '.join(BABBLING_MODES)}",
    "seeds": (
        f"a positive count (seeds 0..N-1) up to {MAX_SEED_COUNT} or a non-empty list of distinct "
        "integers in [0, 2**63 - 1]"
    ),
    "iterations": "a positive integer",
    "checkpoint_every": "a positive integer",
    "eval_placements": "a positive integer (placements per ring)",
    "eval_worlds": (
        f"a list of distinct eval worlds from {', '.join(EVAL_WORLDS)} (each trial's final agent "
        "is also tested there; experiments/trial_dir/eval_worlds.py)"
    ),
    "stick_return": f"one of {', '.join(STICK_RETURNS)}",
    "preset": f"one of {', '.join(PRESETS)}",
    "voice": f"one of {', '.join(TRACTS)}",
    "overrides": 'an object {"world": {...}, "learner": {...}}',
    "study_reference_commands": "a positive integer (random commands per ring)",
    "description": "a string",
    "base": f"the name of a stored profile ({', '.join(stored_profiles())})",
}


def _is_int(value: object) -> TypeGuard[int]:
    return isinstance(value, int) and not isinstance(value, bool)  # True is not a count


def _field_error(name: str, value: object) -> BatchError:
    given = json.dumps(value, default=repr)
    given = given if len(given) <= 60 else given[:57] + "..."  # one line, even for 500 seeds
    return BatchError(f"{name} must be {FIELD_RULES[name]}, got {given}")


@dataclass(frozen=True)
class BatchSpec:
    """Which trials a batch holds and how each is run and evaluated. Every field is checked
    here, without coercion: a batch is refused before anything is written or started."""

    grasps: tuple[str, ...] = GRASPS
    babbling: tuple[str, ...] = (LearnerConfig.babbling,)
    seeds: tuple[int, ...] = (0, 1, 2)
    iterations: int = 1000
    checkpoint_every: int = 1000
    eval_placements: int = 100
    # Eval worlds (experiments/trial_dir/eval_worlds.py) each trial's final agent is tested in
    # besides its own, written into eval-in-NAME/ of the trial (one equal to its own is its own).
    eval_worlds: tuple[str, ...] = ()
    stick_return: str = WorldConfig.stick_return
    preset: str = DEFAULT_PRESET
    voice: str = DEFAULT_TRACT
    overrides: dict = field(default_factory=dict)
    # Random commands per ring behind the study's measure when this batch is reported
    # (`playroom report`, `compare`, `ablations`): the study's 30000 at its scale, fewer for
    # batches of short trials, whose report would otherwise take minutes for seconds of trials.
    study_reference_commands: int = RANDOM_COMMANDS_PER_RING
    description: str = field(default="", compare=False)

    def __post_init__(self) -> None:
        for name, allowed in (("grasps", GRASPS), ("babbling", BABBLING_MODES)):
            values = getattr(self, name)
            if (
                not isinstance(values, tuple)
                or not values
                or any(v not in allowed for v in values)
                or len(set(values)) != len(values)
            ):
                raise _field_error(name, values)
        worlds = self.eval_worlds
        if (
            not isinstance(worlds, tuple)
            or any(w not in EVAL_WORLDS for w in worlds)
            or len(set(worlds)) != len(worlds)
        ):
            raise _field_error("eval_worlds", worlds)
        if not isinstance(self.seeds, tuple) or not self.seeds:
            raise _field_error("seeds", self.seeds)
        # Every log row records its seed in an int64 column (models/checks.py MAX_SEED).
        if not all(_is_int(s) and 0 <= s <= MAX_SEED for s in self.seeds):
            raise _field_error("seeds", self.seeds)
        twice = sorted(s for s, n in Counter(self.seeds).items() if n > 1)
        if twice:
            raise BatchError(f"seeds must be distinct: {twice} given more than once")
        for name in (
            "iterations",
            "checkpoint_every",
            "eval_placements",
            "study_reference_commands",
        ):
            value = getattr(self, name)
            if not _is_int(value) or value <= 0:
                raise _field_error(name, value)
        if self.stick_return not in STICK_RETURNS:
            raise _field_error("stick_return", self.stick_return)
        if self.preset not in PRESETS:
            raise _field_error("preset", self.preset)
        if self.voice not in TRACTS:
            raise _field_error("voice", self.voice)
        if not isinstance(self.overrides, dict) or not all(
            k in ("world", "learner") and isinstance(v, dict) for k, v in self.overrides.items()
        ):
            raise _field_error("overrides", self.overrides)
        if not isinstance(self.description, str):
            raise _field_error("description", self.description)

    def trials(self) -> list[tuple[str, TrialSettings]]:
        """(directory name, settings) of every trial, in a stable order."""
        out = []
        for grasp in self.grasps:
            for babbling in self.babbling:
                for seed in self.seeds:
                    name = f"{grasp}-{babbling}-seed{seed:04d}"
                    settings = TrialSettings(
                        grasp=grasp,
                        iterations=self.iterations,
                        seed=seed,
                        babbling=babbling,
                        checkpoint_every=min(self.checkpoint_every, self.iterations),
                        stick_return=self.stick_return,
                        preset=self.preset,
                        voice=self.voice,
                        overrides=self.overrides,
                    )
                    out.append((name, settings))
        return out

    def check_configs(self) -> None:
        """TrialError unless every trial's world and learner can be built (the overrides fit
        them): one trial per grasp and babbling, since seeds change nothing of that."""
        first = self.trials()[0][1]
        for grasp in self.grasps:
            for babbling in self.babbling:
                full_config(dataclasses.replace(first, grasp=grasp, babbling=babbling))


def spec_record(spec: BatchSpec) -> dict:
    """The spec as a batch directory records it (batch.json): every field, as JSON."""
    return json.loads(json.dumps(dataclasses.asdict(spec)))


def with_overrides(spec: BatchSpec, overrides: dict) -> BatchSpec:
    """`spec` with other overrides (`playroom batch --set`), checked as a config's are."""
    try:
        changed = dataclasses.replace(spec, overrides=overrides)
        changed.check_configs()
    except (BatchError, TrialError) as exc:
        raise BatchError(f"--set: {exc}") from None
    return changed


def _read_fields(text: str, source: str) -> dict:
    """The fields of a batch config's JSON text, each name known."""
    try:
        raw = storage.strict_json(text)
    except (json.JSONDecodeError, storage.DuplicateKeyError) as exc:
        raise BatchError(f"{source} is not valid JSON ({exc})") from None
    if not isinstance(raw, dict):
        raise BatchError(f"{source} must hold a JSON object of the fields {', '.join(FIELD_RULES)}")
    unknown = sorted(set(raw) - set(FIELD_RULES))
    if unknown:
        raise BatchError(
            f"{source}: unknown field(s) {', '.join(unknown)}; known: {', '.join(FIELD_RULES)}"
        )
    return dict(raw)


def _with_base(given: dict, source: str) -> dict:
    """A config's fields on top of its "base" profile's, if it names one: what it leaves out is
    the base's (its own description aside), its overrides added to the base's per section."""
    if "base" not in given:
        return given
    base = given.pop("base")
    if not isinstance(base, str) or base not in stored_profiles():
        raise BatchError(f"{source}: {_field_error('base', base)}")
    text = resources.files("experiments.batches").joinpath("profiles", f"{base}.json").read_text()
    fields = _read_fields(text, f"profile {base}")
    if "base" in fields:  # one level: a profile is read as it stands
        raise BatchError(f"profile {base} has a base itself: a base must be a whole profile")
    fields.pop("description", None)
    mine, theirs = given.get("overrides", {}), fields.get("overrides", {})
    both = (mine, theirs, *getattr(mine, "values", list)(), *getattr(theirs, "values", list)())
    if all(isinstance(o, dict) for o in both):  # else left for BatchSpec to refuse
        mine = {k: {**theirs.get(k, {}), **mine.get(k, {})} for k in {*theirs, *mine}}
    return {**fields, **given, "overrides": mine}


def load_spec(
    profile: str | None = None, config_file: str | os.PathLike | None = None
) -> BatchSpec:
    """A stored profile (experiments/batches/profiles/NAME.json) or a JSON file of the same form,
    checked whole: BatchError names the first setting that is not what it may be."""
    if (profile is None) == (config_file is None):
        raise BatchError("give exactly one of --profile NAME or --config FILE")
    if profile is not None:
        if profile not in stored_profiles():
            choices = ", ".join(stored_profiles())
            raise BatchError(f"unknown profile {profile!r}: choose one of {choices}")
        profiles = resources.files("experiments.batches").joinpath("profiles")
        text = profiles.joinpath(f"{profile}.json").read_text()
        source = f"profile {profile}"
    else:
        assert config_file is not None  # exactly one of the two was given
        path = Path(config_file)
        if not path.is_file():
            raise BatchError(f"batch config {path} does not exist")
        try:
            text, source = path.read_text(), str(path)
        except (OSError, UnicodeDecodeError) as exc:
            raise BatchError(f"cannot read batch config {path}: {exc}") from None
    given = _with_base(_read_fields(text, source), source)
    # JSON has lists where the spec has tuples; nothing else is converted.
    for name in ("grasps", "babbling", "seeds", "eval_worlds"):
        if isinstance(given.get(name), list):
            given[name] = tuple(given[name])
    seeds = given.get("seeds")
    if _is_int(seeds):
        if not 0 < seeds <= MAX_SEED_COUNT:
            raise BatchError(f"{source}: {_field_error('seeds', seeds)}")
        given["seeds"] = tuple(range(seeds))
    try:
        spec = BatchSpec(**given)
        spec.check_configs()
    except (BatchError, TrialError) as exc:
        raise BatchError(f"{source}: {exc}") from None
    return spec
