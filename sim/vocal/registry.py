"""The vocal tracts by name: what the room builds its voice from.

`REGISTRY` (models/tracts.py, the one table) maps each name to "module:Class"; `load` imports
the class only when a tract of that name is asked for, so naming or checking a tract imports no
synthesizer, and a tract whose module fails to import breaks only itself. The grasp backends'
registry has the same shape (sim/grasping/registry.py).
"""

from __future__ import annotations

from typing import cast

from models.registry import load_registered
from models.tracts import REGISTRY, TRACTS
from sim.config import WorldConfig
from sim.vocal.config import VoiceConfig
from sim.vocal.voice import Voice

__all__ = ["REGISTRY", "TRACTS", "load", "make_tract"]


def load(name: str) -> type[Voice]:
    """The tract class called `name`, imported now; ValueError naming the choices."""
    return cast("type[Voice]", load_registered(REGISTRY, name, "vocal tract", Voice))


def make_tract(name: str, exact: bool, config: VoiceConfig, world: WorldConfig) -> Voice:
    """The vocal tract called `name` (its exact path if `exact`); ValueError naming the
    choices. DIVA without its installed data: DivaDataMissing, never another tract."""
    return load(name)(exact=exact, config=config, world=world)
