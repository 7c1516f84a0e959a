"""The names of the grasp backends and the default one, without importing MuJoCo.

The command line offers these names and the settings of a trial or a batch are checked against
them before any world is built. They are the keys of `sim.grasping.registry.REGISTRY`, the one
table of the backends, which imports no backend: a new backend is one line there.
"""

from __future__ import annotations

from sim.grasping.registry import REGISTRY

GRASPS: tuple[str, ...] = tuple(REGISTRY)
# The study's rules: what `Playroom()`, `playroom run`, `random` and `render` use unless told.
DEFAULT_GRASP = "kinematic"
