"""`--set section.name=value`: one setting of the world or the learner changed from the
command line (`playroom run`, `batch`, `random`), as a batch config's "overrides" change it.

The value is read as JSON when it is JSON (0.05, true, [1, 2], "text"), else taken as a string
(`--set world.stick_return=never` needs no quotes). Only the form is checked here: the names
and values are checked by the configs, as every override is (experiments/run/trial_config.py)."""

from __future__ import annotations

import argparse
import copy
import json
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:  # loaded when `random_world` runs: building the parser loads no simulator
    from sim.config import WorldConfig

# The sections an override may change (experiments/run/settings.py OVERRIDABLE).
SECTIONS = ("world", "learner")


def dotted_setting(text: str) -> tuple[str, str, Any]:
    """argparse type of `--set`: 'learner.exploration_sigma=0.05' -> ('learner',
    'exploration_sigma', 0.05)."""
    target, equals, raw = text.partition("=")
    section, dot, name = target.strip().partition(".")
    if not equals or not dot or not name.isidentifier():
        raise argparse.ArgumentTypeError(
            f"expected SECTION.NAME=VALUE (e.g. learner.exploration_sigma=0.05), got {text!r}"
        )
    if section not in SECTIONS:
        raise argparse.ArgumentTypeError(
            f"unknown section {section!r} in {text!r}: one of {', '.join(SECTIONS)}"
        )
    try:
        value = json.loads(raw)
    except json.JSONDecodeError:
        value = raw  # a bare word: a string
    return section, name, value


def merged(overrides: dict, settings: list[tuple[str, str, Any]] | None) -> dict:
    """`overrides` ({"world": {...}, "learner": {...}}, a batch config's) with each `--set`
    applied (over the config's own); a new dict, the given one left as it is. ValueError (one
    line) for a setting given twice: which of the two was meant cannot be told."""
    out = copy.deepcopy(overrides)
    given: set[tuple[str, str]] = set()
    for section, name, value in settings or []:
        if (section, name) in given:
            raise ValueError(f"--set {section}.{name} is given twice: give each setting once")
        given.add((section, name))
        out.setdefault(section, {})[name] = value
    return out


def random_world(
    grasp: str, preset: str, settings: list[tuple[str, str, Any]] | None
) -> WorldConfig:
    """The WorldConfig of `playroom random`: the preset's world with the `--set` settings,
    which must be the world's, allowed, and read by the backend `grasp`'s rules; ValueError
    (one line) otherwise."""
    from sim.config import inert_settings, world_preset

    changes = merged({}, settings)
    others = sorted(set(changes) - {"world"})
    if others:
        raise ValueError(
            f"random takes world settings only (--set world.NAME=VALUE), not {others[0]}"
        )
    world = changes.get("world", {})
    inert = inert_settings(grasp, world)
    if inert:
        raise ValueError(f"world.{inert[0]} changes nothing on the {grasp} backend")
    try:
        return world_preset(preset, **world)
    except TypeError as exc:  # an unknown field
        raise ValueError(f"--set: {exc}") from None
