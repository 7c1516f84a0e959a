"""The names of the grasp backends and the default one, without importing MuJoCo.

The command line and the trial settings check a grasp against these names before any world is
built. `sim.grasping.registry` maps each name to its backend and refuses to import if the two
lists differ, so a new backend is added there and here.
"""

from __future__ import annotations

GRASPS: tuple[str, ...] = ("kinematic", "physical")
# The study's rules: what `Playroom()`, `playroom run`, `random` and `render` use unless told.
DEFAULT_GRASP = "kinematic"
