"""The playroom world: MuJoCo physics, DMPs, grasp rules, caregiver, vocal tract, dm_control task.

`sim` knows nothing of learning, and importing it leaves the process environment alone
(sim/process_environment.py): which OpenGL backend MuJoCo loads is the caller's choice
(`MUJOCO_GL`, see experiments/video/gl.py), and MuJoCo is imported, its GL library checked
first, only where a module needs it (sim/mujoco_import.py). `Playroom` and `Feedback` are loaded
on first use, so that `sim.config` and the other plain modules can be imported without MuJoCo.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from sim.gl_library import gl_library_problem
from sim.process_environment import environment_kept

if TYPE_CHECKING:
    from sim.playroom import Feedback, Playroom

__all__ = ["Feedback", "Playroom", "environment_kept", "gl_library_problem"]


def __getattr__(name: str) -> Any:
    if name in ("Feedback", "Playroom"):
        try:
            from sim import playroom
        except AttributeError as exc:
            # An AttributeError raised here would read as "cannot import name 'Playroom'",
            # hiding what failed while the room's modules were imported.
            raise ImportError(f"importing sim.playroom failed: {exc}") from exc
        return getattr(playroom, name)
    raise AttributeError(f"module 'sim' has no attribute {name!r}")
