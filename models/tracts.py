"""The vocal tracts by name, lazily: name -> "module:Class", read without importing a synthesizer.

The one table of the tracts. The command line, the trial settings and `sim.config.WorldConfig`
check a tract against its names before any voice is built; `sim.vocal.registry.load` imports a
tract's class only when one is built (as Gymnasium registers its environments). It lives here,
not beside the tracts, because `sim.config` reads it and sim/vocal/ imports `sim.config`.

Adding a tract: its module (a `sim.vocal.voice.Voice` subclass whose `name` is its key here)
and one line in `REGISTRY`; tests/sim/vocal/test_tract_contract.py then runs it.
"""

from __future__ import annotations

REGISTRY: dict[str, str] = {
    # VocalTractLab's articulatory synthesizer, this project's (its data ships with it).
    "vtl": "sim.vocal.vtl.tract:VocalTract",
    # DIVA's fitted formant map, the synthesizer the study ran (its data is the user's).
    "diva": "sim.vocal.diva.tract:DivaTract",
}
TRACTS: tuple[str, ...] = tuple(REGISTRY)
# The tract of every trial written before the choice existed: their config.json names none.
DEFAULT_TRACT = "vtl"
