"""The caregiver's body: where she stands, and how she brings a toy toward the agent.

What she hears and says (words) is the voice's part (sim/vocal/words.py); this module moves
things. In the physical backend she carries the toy with her hand, a mocap body welded to the
toy; in the kinematic backend the toy is placed directly, as in the study.
"""

from __future__ import annotations

import mujoco
import numpy as np

from sim.config import DEFAULT_WORLD, WorldConfig
from sim.physics import TOYS, PlayroomPhysics


class Caregiver:
    """Places the caregiver and moves a toy toward the midpoint between her and the arm's base.

    The study moves the toy `bring_rate` (1%) of the remaining way at each control step, about
    40% of the way over one 50-step movement (protocol.md).
    """

    def __init__(self, physical: bool, config: WorldConfig = DEFAULT_WORLD) -> None:
        self.physical = physical
        self.config = config
        self.bringing: int | None = None  # index of the toy she is bringing
        self._collision_bits = (0, 0)  # contype, conaffinity of the toy she carries
        self._damping = np.zeros(3)  # its joints' damping on the table

    def place(self, physics: PlayroomPhysics, rng: np.random.Generator) -> None:
        """A new position, uniform in the square [-box, box]^2."""
        box = self.config.caregiver_box
        position = rng.uniform(-box, box, size=2)
        d = physics.data.ptr
        d.mocap_pos[physics.caregiver_mocap, :2] = position
        d.mocap_pos[physics.caregiver_hand_mocap, :2] = position  # her hand rests by her

    def target(self, physics: PlayroomPhysics) -> np.ndarray:
        """(2,) midpoint between the caregiver and the arm's base at (0, 0)."""
        return physics.caregiver_position() / 2.0

    def start_bringing(self, physics: PlayroomPhysics, toy: int) -> None:
        """Take toy `toy` (0-based) and bring it over the coming control steps."""
        self.bringing = toy
        if not self.physical:
            return
        m, d = physics.model.ptr, physics.data.ptr
        hand = physics.caregiver_hand_mocap
        d.mocap_pos[hand, :2] = physics.toy_positions()[toy]
        eq = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_EQUALITY, f"caregiver_{TOYS[toy]}")
        # Her hand sits exactly on the toy, so the weld's relative pose is the identity apart
        # from the height difference between her hand and the toy.
        mujoco.mj_kinematics(m, d)
        body = physics.toy_bodies[toy]
        m.eq_data[eq, 0:3] = 0.0
        m.eq_data[eq, 3:6] = d.xpos[body] - d.mocap_pos[hand]
        m.eq_data[eq, 6:10] = (1.0, 0.0, 0.0, 0.0)
        d.eq_active[eq] = 1
        # She lifts the toy: while carried it touches nothing, as a toy carried above the
        # table would not (dragged along the table it would sweep the stick out of reach).
        geom = physics.toy_geoms[toy]
        self._collision_bits = (int(m.geom_contype[geom]), int(m.geom_conaffinity[geom]))
        m.geom_contype[geom] = m.geom_conaffinity[geom] = 0
        dofs = physics.object_dof[1 + toy]
        self._damping = m.dof_damping[dofs].copy()
        m.dof_damping[dofs] = 0.0  # no table friction above the table

    def before_step(self, physics: PlayroomPhysics) -> None:
        """Move the toy she is bringing `bring_rate` of the remaining way."""
        if self.bringing is None:
            return
        rate = self.config.caregiver_bring_rate
        target = self.target(physics)
        d = physics.data.ptr
        if self.physical:
            hand = physics.caregiver_hand_mocap
            d.mocap_pos[hand, :2] += rate * (target - d.mocap_pos[hand, :2])
        else:
            poses = physics.object_poses()
            poses[1 + self.bringing, :2] += rate * (target - poses[1 + self.bringing, :2])
            physics.set_object_poses(poses)

    def stop(self, physics: PlayroomPhysics) -> None:
        """Put the toy down where it is."""
        if self.bringing is None:
            return
        if self.physical:
            m, d = physics.model.ptr, physics.data.ptr
            eq = mujoco.mj_name2id(
                m, mujoco.mjtObj.mjOBJ_EQUALITY, f"caregiver_{TOYS[self.bringing]}"
            )
            d.eq_active[eq] = 0
            geom = physics.toy_geoms[self.bringing]
            m.geom_contype[geom], m.geom_conaffinity[geom] = self._collision_bits
            m.dof_damping[physics.object_dof[1 + self.bringing]] = self._damping
            d.qvel[physics.object_dof] = 0.0
            d.mocap_pos[physics.caregiver_hand_mocap, :2] = physics.caregiver_position()
        self.bringing = None
