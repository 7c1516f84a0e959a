"""The vocal tracts by name: what the room builds its voice from.

Adding a tract: a module with a `sim.vocal.voice.Voice` subclass, its class here and its name in
models/tracts.py (which the settings check without importing any synthesizer).
"""

from __future__ import annotations

from models.tracts import TRACTS as TRACT_NAMES
from sim.config import WorldConfig
from sim.vocal.config import VoiceConfig
from sim.vocal.diva.tract import DivaTract
from sim.vocal.tract import VocalTract
from sim.vocal.voice import Voice

TRACTS: dict[str, type[Voice]] = {cls.name: cls for cls in (VocalTract, DivaTract)}
if tuple(TRACTS) != TRACT_NAMES:
    raise ImportError(f"models/tracts.py lists {TRACT_NAMES}, the registry {tuple(TRACTS)}")


def make_tract(name: str, exact: bool, config: VoiceConfig, world: WorldConfig) -> Voice:
    """The vocal tract called `name` (its exact path if `exact`); ValueError naming the
    choices. DIVA without its installed data: DivaDataMissing, never another tract."""
    if name not in TRACTS:
        raise ValueError(f"unknown vocal tract {name!r}: choose one of {list(TRACTS)}")
    return TRACTS[name](exact=exact, config=config, world=world)
