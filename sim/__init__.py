"""The playroom world: MuJoCo physics, DMPs, grasp rules, caregiver, vocal tract, dm_control task.

`sim` knows nothing of learning. Offscreen rendering defaults to EGL (works with Mesa's EGL on
machines without a GPU); set MUJOCO_GL=osmesa before importing to use OSMesa instead.
"""

import os

os.environ.setdefault("MUJOCO_GL", "egl")

from sim.playroom import Feedback, Playroom  # noqa: E402

__all__ = ["Feedback", "Playroom"]
