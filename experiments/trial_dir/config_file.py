"""config.json across versions, and the identity of the trial it makes: settings added after
trials were written, and what a trial's checkpoints, log chunks, memory segments and evaluations
carry of it (`trial_identity`), so that a file of another trial is told apart; what every log
row carries of it (`source_of`), and where two configs differ (`config_differences`).

A trial's config.json holds every setting it ran with. A setting added later (the vocal tract,
`voice`) is absent from older trials, which ran with the value the setting declares beside its
field as `before` (`dataclasses.field(metadata={BEFORE: ...})` in sim/config.py and
sim/vocal/config.py): `with_added_settings` fills it in when a config is read, so an old trial
resumes, is evaluated and compared as it is; `identity_form` leaves such a setting out while it
has that value, so that an old trial's checkpoints (which carry a hash of its config) stay its
own. Adding a world setting is its field with its `before`; nothing here changes.

The trial's own settings (experiments/run/settings.py) lie above this module, in the stage that
runs trials, which the readers of trials may not import; the only ones added since are choices
of a world setting of their name (WORLD_CHOICES), which share its history.
Pure functions of dicts, and the configs' plain
dataclasses (no simulator): every reader of config.json can use them.
"""

from __future__ import annotations

import copy
import dataclasses
import hashlib
import json
import os
from pathlib import Path
from typing import Any

from experiments.trial_dir.log_schema import SOURCE_COLUMNS
from sim.config import BEFORE, WorldConfig
from sim.vocal.config import VoiceConfig

# The sections of config.json whose settings declare their earlier values beside their fields.
SECTIONS = {"world": WorldConfig, "voice": VoiceConfig}
# The trial settings that choose the world setting of their name (experiments/run/settings.py
# copies them into the world): each ran, before it existed, with its world setting's value.
WORLD_CHOICES = ("stick_return", "voice")


def added_settings() -> dict[str, object]:
    """Dotted key -> the value every trial written before the setting existed ran with, as the
    settings declare it (module docstring)."""
    added = {
        f"{section}.{field.name}": field.metadata[BEFORE]
        for section, cls in SECTIONS.items()
        for field in dataclasses.fields(cls)
        if BEFORE in field.metadata
    }
    for name in WORLD_CHOICES:
        if f"world.{name}" in added:
            added[f"trial.{name}"] = added[f"world.{name}"]
    return added


def with_added_settings(config: dict) -> dict:
    """A copy of a config with every added setting it lacks set to its earlier value."""
    out = copy.deepcopy(config)
    for key, value in added_settings().items():
        node, last = _section(out, key)
        if node is not None and last not in node:
            node[last] = value
    return out


def identity_form(config: dict) -> dict:
    """A copy of a config without the added settings that hold their earlier value."""
    out = copy.deepcopy(config)
    for key, value in added_settings().items():
        node, last = _section(out, key)
        if node is not None and node.get(last, value) == value:
            node.pop(last, None)
    return out


def _section(config: dict, key: str) -> tuple[dict | None, str]:
    """The dict that holds a dotted key's last part (None if the config lacks it), and that
    part."""
    *parents, last = key.split(".")
    node: object = config
    for parent in parents:
        node = node.get(parent) if isinstance(node, dict) else None
    return (node if isinstance(node, dict) else None), last


class UnknownSettingError(ValueError):
    """A config.json naming a setting no version of the project wrote (one line names it)."""


def check_known(config: dict, path: object) -> None:
    """UnknownSettingError naming the first setting of a section declared here (SECTIONS: the
    world and the voice) that no field declares: a config.json edited by hand, which every
    reader names as such rather than as another trial's (its identity hash changes with it)."""
    for section, cls in SECTIONS.items():
        values = config.get(section)
        if isinstance(values, dict):
            known = {f.name for f in dataclasses.fields(cls)}
            unknown = sorted(set(values) - known)
            if unknown:
                raise UnknownSettingError(
                    f"{path} has an unknown setting {section}.{unknown[0]}, which no version of "
                    "the project writes: remove it (an edit by hand?)"
                )


# Settings a resume may change: a trial can be extended to more iterations.
EXTENSIBLE = ("trial.iterations",)
# What an identity leaves out of its trial's config: the settings a resume may change, and the
# package version. The version says which code wrote config.json, not which trial it is; in the
# identity it would orphan every checkpoint at each release (whether a trial may be resumed by
# another version is for the config comparison on resume to say).
_NOT_IDENTITY = (*EXTENSIBLE, "package_version")


def trial_identity(config: dict) -> dict:
    """What a trial's checkpoints and log chunks carry of it: the seed, and a hash of the
    trial's config without the settings that are not the trial's identity (_NOT_IDENTITY)."""
    kept = identity_form(config)  # a copy, as older trials' configs would read
    for key in _NOT_IDENTITY:
        *parents, last = key.split(".")
        node = kept
        for parent in parents:
            node = node.get(parent, {})
        node.pop(last, None)
    text = json.dumps(kept, sort_keys=True, separators=(",", ":"))
    digest = hashlib.sha256(text.encode()).hexdigest()[:12]
    return {"seed": config["trial"]["seed"], "config": digest}


def identity_text(identity: object) -> str:
    """An identity as messages show it: "seed 5, config 0123456789ab"."""
    found = identity if isinstance(identity, dict) else {}
    return f"seed {found.get('seed', '?')}, config {found.get('config', '?')}"


def config_differences(a: dict, b: dict, prefix: str = "") -> list[tuple[str, Any, Any]]:
    """(dotted key, value in a, value in b) of every setting where two nested configs differ."""
    out = []
    for k in sorted(set(a) | set(b)):
        va, vb = a.get(k), b.get(k)
        if isinstance(va, dict) and isinstance(vb, dict):
            out += config_differences(va, vb, f"{prefix}{k}.")
        elif va != vb:
            out.append((f"{prefix}{k}", va, vb))
    return out


def source_of(trial_dir: str | os.PathLike, config: dict) -> dict[str, str | int]:
    """The source columns of a trial's rows (log_schema.SOURCE_COLUMNS), from its directory
    and config (of any version: a trial older than the voice setting ran with VocalTractLab)."""
    trial = with_added_settings(config)["trial"]
    name = Path(trial_dir).resolve().name
    values = (name, int(trial["seed"]), str(trial["grasp"]), str(trial["voice"]))
    return dict(zip(SOURCE_COLUMNS, values, strict=True))
