"""The playroom world: MuJoCo physics, DMPs, grasp rules, caregiver, vocal tract, dm_control task.

`sim` knows nothing of learning, and importing it leaves the process environment alone: which
OpenGL backend MuJoCo loads is the caller's choice (`MUJOCO_GL`, see experiments/video/gl.py).
`Playroom` and `Feedback` are loaded on first use, so that `sim.config` and the other plain
modules can be imported without MuJoCo.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from sim.playroom import Feedback, Playroom

__all__ = ["Feedback", "Playroom"]


def __getattr__(name: str) -> Any:
    if name in __all__:
        from sim import playroom

        return getattr(playroom, name)
    raise AttributeError(f"module 'sim' has no attribute {name!r}")
