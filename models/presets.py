"""The presets a trial chooses from, and the one default of every entry point.

A preset names a whole way of behaving, of the world and the learner together: "study" moves,
grasps and learns as the study's code did (docs/protocol.md §11); "project" keeps this project's
earlier choices. `sim.config.world_preset` and `learner.config.learner_preset` say what each
means for their configs; both read the names from here, since sim and learner never import each
other. `Playroom()`, `Agent()`, `playroom run`, `random`, `render` and batches all take
DEFAULT_PRESET when none is given.
"""

from __future__ import annotations

PRESETS: tuple[str, ...] = ("study", "project")
# The study's condition: what the replication and the README's examples run.
DEFAULT_PRESET = "study"
