"""How closely the physical arm's hand follows its DMP targets: the measurement behind the
servo gains of models/playroom.xml."""

from __future__ import annotations

import numpy as np

from models.layout import ARM_DIM, N_STEPS
from sim.config import DEFAULT_WORLD, WorldConfig
from sim.dmp import arm_trajectory
from sim.kinematics import hand_positions
from sim.mujoco_import import mujoco
from sim.physics import CONTROL_SUBSTEPS, PlayroomPhysics


def hand_tracking_errors(
    n_commands: int = 1000, seed: int = 0, config: WorldConfig = DEFAULT_WORLD
) -> np.ndarray:
    """(n_commands, n_steps) distance (m) between the simulated hand after each control step
    and the hand of the target joint angles, for random commands in [-1, 1]^21.

    Contacts are switched off: this measures the servos, not collisions with objects.
    """
    physics = PlayroomPhysics.load()
    m, d = physics.model.ptr, physics.data.ptr
    m.opt.disableflags |= mujoco.mjtDisableBit.mjDSBL_CONTACT
    rng = np.random.default_rng(seed)
    errors = np.empty((n_commands, N_STEPS))
    hand = np.empty((N_STEPS, 2))
    for i in range(n_commands):
        targets = arm_trajectory(rng.uniform(-1.0, 1.0, ARM_DIM), config)
        mujoco.mj_resetDataKeyframe(m, d, physics.home_key)
        mujoco.mj_forward(m, d)
        for k in range(N_STEPS):
            d.ctrl[:] = targets[:, k]
            mujoco.mj_step(m, d, CONTROL_SUBSTEPS)
            mujoco.mj_kinematics(m, d)
            hand[k] = d.site_xpos[physics.hand_site, :2]
        errors[i] = np.linalg.norm(hand - hand_positions(targets, config), axis=1)
    return errors
