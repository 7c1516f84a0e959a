"""The playroom world: MuJoCo physics, DMPs, grasp rules, caregiver, vocal tract, dm_control task.

`sim` knows nothing of learning, and importing it leaves the process environment alone: which
OpenGL backend MuJoCo loads is the caller's choice (`MUJOCO_GL`, see experiments/gl.py).
"""

from sim.playroom import Feedback, Playroom

__all__ = ["Feedback", "Playroom"]
