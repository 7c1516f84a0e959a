"""The grasp backends by name, lazily: name -> "module:Class", as Gymnasium registers its
environments.

`REGISTRY` is the one table of the backends. Naming or checking a backend (the command line,
the trial settings, a batch's spec: `names.GRASPS` is this table's keys) imports none of them,
so neither MuJoCo nor numba; `load` imports a backend's module only when a room is built with
it (`Playroom(grasp=...)` loads the class, then the class's `physics_class`). A backend whose
module fails to import breaks only itself. The vocal tracts' registry has the same shape
(models/tracts.py, sim/vocal/registry.py).

Adding a backend: its module (a `sim.grasping.base.GraspBackend` subclass whose `name` is its
key here, declaring its parts, which the playroom builds: its physics, the caregiver's carrying,
its grasp rule) and one line below; tests/sim/test_backend_contract.py then runs it.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, cast

from models.registry import load_registered

if TYPE_CHECKING:
    from sim.grasping.base import GraspBackend

REGISTRY: dict[str, str] = {
    # The study's distance rules, stepped and in closed form (docs/protocol.md §5, §6).
    "kinematic": "sim.grasping.kinematic:KinematicGrasp",
    # Grasping through MuJoCo contacts and welds (docs/protocol.md §11 D16).
    "physical": "sim.grasping.physical:PhysicalGrasp",
}


def load(name: str) -> type[GraspBackend]:
    """The backend class registered as `name`, its module imported now; ValueError naming
    the choices."""
    from sim.grasping.base import GraspBackend  # (MuJoCo: only when a room is built)

    backend = load_registered(REGISTRY, name, "grasp backend", GraspBackend)
    return cast("type[GraspBackend]", backend)
