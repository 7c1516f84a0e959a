"""The arm's position servos alone: the joint angles the physical model's servos reach while
tracking joint targets, with the arm touching nothing (WorldConfig.arm_dynamics "servo", a rung
of the contact ladder, docs/world.md: the kinematic rules acting on a simulated arm).

The arm is the physical room's own (models/playroom.xml: its links, joints, armature, damping,
limits and actuators, kp and damping ratio), compiled without the objects, the caregiver, the
welds and the sensors, and with contacts off. Its joints are coupled to nothing else in the
room, so in a room whose objects it never touches the physical backend's arm follows the same
path: the same MuJoCo calls in the same order (`PlayroomPhysics.advance`: mj_step2, then
mj_step, then mj_step1, each control step) give the same numbers, bit for bit
(tests/sim/test_arm_servo.py). The arm model has 3 degrees of freedom against the room's 15:
500 steps cost about 1 ms against 2 ms.
"""

from __future__ import annotations

import functools

import numpy as np

from models import playroom_xml
from models.layout import N_JOINTS
from sim.mujoco_import import mujoco
from sim.physics import CONTROL_SUBSTEPS

# The body of models/playroom.xml whose subtree is the arm; every other body of the world is
# left out of the arm's model.
ARM_ROOT = "base"


@functools.cache
def arm_model() -> mujoco.MjModel:
    """The arm of the packaged models/playroom.xml alone (the model every room loads), compiled
    once per process; contacts off."""
    spec = mujoco.MjSpec.from_file(str(playroom_xml()))
    # The equalities, sensors and keyframes name the removed bodies, geoms and joints.
    for element in [*spec.equalities, *spec.sensors, *spec.keys]:
        spec.delete(element)
    for body in [b for b in spec.worldbody.bodies if b.name != ARM_ROOT]:
        spec.delete(body)
    model = spec.compile()
    if model.nu != N_JOINTS or model.nq != N_JOINTS:
        raise ValueError(
            f"the arm of models/playroom.xml has {model.nq} joints and {model.nu} actuators, "
            f"not {N_JOINTS}: the body {ARM_ROOT!r} must hold the arm and nothing else"
        )
    model.opt.disableflags |= mujoco.mjtDisableBit.mjDSBL_CONTACT  # the arm touches nothing
    return model


class ArmServo:
    """The servo-driven arm, one movement at a time: `reset` puts it at rest, `step` runs one
    control step toward its targets and returns the joint angles after it."""

    def __init__(self) -> None:
        self.model = arm_model()
        self.data = mujoco.MjData(self.model)
        self.reset()

    def reset(self) -> None:
        """The arm at rest, still, with no control, as every movement of a room starts
        (`PlayroomPhysics.rest_arm`); the position-dependent quantities computed, as the room's
        placements leave them before a movement."""
        d = self.data
        d.qpos[:] = 0.0
        d.qvel[:] = 0.0
        d.ctrl[:] = 0.0
        mujoco.mj_forward(self.model, d)

    def step(self, targets: np.ndarray) -> np.ndarray:
        """One control step with the servos' targets (3,) rad relative to rest: the (3,) joint
        angles after it."""
        m, d = self.model, self.data
        d.ctrl[:] = targets
        mujoco.mj_step2(m, d)
        mujoco.mj_step(m, d, CONTROL_SUBSTEPS - 1)
        mujoco.mj_step1(m, d)
        return d.qpos.copy()

    def path(self, targets: np.ndarray) -> np.ndarray:
        """(3, n) joint angles after each control step of a movement from rest, tracking
        targets (3, n): the same numbers as `reset` then `step` at each step."""
        self.reset()
        angles = np.empty(targets.shape)
        for k in range(targets.shape[1]):
            angles[:, k] = self.step(targets[:, k])
        return angles
