"""The vocal tracts by name: what the room builds its voice from.

Adding a tract: a module with a `sim.vocal.voice.Voice` subclass, and its class here.
"""

from __future__ import annotations

from sim.config import WorldConfig
from sim.vocal.config import VoiceConfig
from sim.vocal.tract import VocalTract
from sim.vocal.voice import Voice

TRACTS: dict[str, type[Voice]] = {cls.name: cls for cls in (VocalTract,)}
# The study's tract, and the only one a trial uses so far: config.json names none.
DEFAULT_TRACT = "vtl"


def make_tract(name: str, exact: bool, config: VoiceConfig, world: WorldConfig) -> Voice:
    """The vocal tract called `name` (its exact path if `exact`); ValueError naming the
    choices."""
    if name not in TRACTS:
        raise ValueError(f"unknown vocal tract {name!r}: choose one of {list(TRACTS)}")
    return TRACTS[name](exact=exact, config=config, world=world)
