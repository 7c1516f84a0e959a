"""The names of the vocal tracts and the default one, without importing a synthesizer.

The command line, the trial settings and `sim.config.WorldConfig` (which sim/vocal/ imports, so the
names cannot live there) check a tract against these
names before any voice is built. `sim.vocal.registry` maps each name to its class and refuses to
import if the two lists differ, so a new tract is added there and here.
"""

from __future__ import annotations

# "vtl": VocalTractLab's articulatory synthesizer (this project's); "diva": DIVA's fitted
# formant map, the synthesizer the study ran (sim/vocal/diva/; its data is the user's).
TRACTS: tuple[str, ...] = ("vtl", "diva")
# The tract of every trial written before the choice existed: their config.json names none.
DEFAULT_TRACT = "vtl"
