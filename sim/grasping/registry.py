"""The grasp backends by name: what `Playroom(grasp=...)` builds (it loads the backend's
`physics_class`, then makes the backend with the physics' `ModelEdits`).

`names.GRASPS` lists the same names without importing MuJoCo (the command line and the trial
settings read it); this module refuses to import if the two disagree.
"""

from __future__ import annotations

from sim.grasping.base import GraspBackend
from sim.grasping.kinematic import KinematicGrasp
from sim.grasping.names import GRASPS
from sim.grasping.physical import PhysicalGrasp

BACKENDS: dict[str, type[GraspBackend]] = {cls.name: cls for cls in (KinematicGrasp, PhysicalGrasp)}

if tuple(BACKENDS) != GRASPS:
    raise ImportError(
        f"sim.grasping.registry holds the backends {tuple(BACKENDS)} but "
        f"sim.grasping.names.GRASPS lists {GRASPS}: list each backend in both, in one order"
    )


def backend_class(name: str) -> type[GraspBackend]:
    """The backend class called `name`; ValueError naming the choices."""
    if name not in BACKENDS:
        raise ValueError(f"unknown grasp backend {name!r}: choose one of {list(BACKENDS)}")
    return BACKENDS[name]
