"""The one owner of run-time edits of the playroom model: welds, collision bits, damping.

Grasping and the caregiver's carrying (sim/grasping/physical.py) both change the compiled model
while a movement runs: a weld holds what is grasped or carried, a held object stops colliding
with what holds it, a lifted object loses the table's damping. Each asks through this class
under its own name, and the model's arrays are always recomputed from the compiled values plus
every owner's current edits, so the result does not depend on the order in which owners edit
or clear: clearing one owner's edits never undoes another's.
"""

from __future__ import annotations

from collections import defaultdict
from dataclasses import dataclass, field

import numpy as np

from sim.mujoco_import import mujoco
from sim.physics import PlayroomPhysics


@dataclass
class _Edits:
    welds: set[int] = field(default_factory=set)  # equality ids made active
    lifted: set[int] = field(default_factory=set)  # rows of PlayroomPhysics.object_dof
    intangible: set[int] = field(default_factory=set)  # geoms that touch nothing
    ignored: set[tuple[int, int]] = field(default_factory=set)  # (geom, collision bit) removed


class ModelEdits:
    """Edits of `physics.model` by named owners ("grasp", "caregiver")."""

    def __init__(self, physics: PlayroomPhysics) -> None:
        self.physics = physics
        m = physics.model.ptr
        self._contype = m.geom_contype.copy()
        self._conaffinity = m.geom_conaffinity.copy()
        self._damping = m.dof_damping.copy()
        self._by_owner: dict[str, _Edits] = defaultdict(_Edits)

    def compiled_contype(self, geom: int) -> int:
        """The geom's collision type as compiled from the MJCF (its bit, for our geoms)."""
        return int(self._contype[geom])

    def weld_here(self, owner: str, equality: str, keep_orientation: bool = True) -> None:
        """Activate the named weld equality at its bodies' current relative pose (with their
        current relative orientation, or aligned if not `keep_orientation`).

        A weld's reference pose is fixed at compile time, and activating it unchanged snaps the
        second body to that pose (a stick at (0.30, 0.10) jumped to (0.61, 0.20)); so the
        current pose of body2 in body1's frame is written into `eq_data` first.
        """
        m, d = self.physics.model.ptr, self.physics.data.ptr
        eq = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_EQUALITY, equality)
        if eq < 0:
            raise ValueError(f"the model has no equality named {equality!r}")
        b1, b2 = m.eq_obj1id[eq], m.eq_obj2id[eq]
        rel_pos, rel_quat, inv_q1 = np.zeros(3), np.zeros(4), np.zeros(4)
        mujoco.mju_negQuat(inv_q1, d.xquat[b1])
        mujoco.mju_rotVecQuat(rel_pos, d.xpos[b2] - d.xpos[b1], inv_q1)
        if keep_orientation:
            mujoco.mju_mulQuat(rel_quat, inv_q1, d.xquat[b2])
        else:
            rel_quat[0] = 1.0
        m.eq_data[eq, 0:3] = 0.0
        m.eq_data[eq, 3:6] = rel_pos
        m.eq_data[eq, 6:10] = rel_quat
        d.eq_active[eq] = 1
        self._by_owner[owner].welds.add(int(eq))

    def lift(self, owner: str, object_row: int) -> None:
        """Object `object_row` (of OBJECTS) is off the table: no table damping on its joints."""
        self._by_owner[owner].lifted.add(int(object_row))
        self._apply()

    def make_intangible(self, owner: str, geom: int) -> None:
        """Geom `geom` touches nothing (an object carried above the table)."""
        self._by_owner[owner].intangible.add(int(geom))
        self._apply()

    def ignore(self, owner: str, geom: int, bit: int) -> None:
        """Geom `geom` no longer collides with geoms whose contype has `bit`."""
        self._by_owner[owner].ignored.add((int(geom), int(bit)))
        self._apply()

    def clear(self, owner: str) -> None:
        """Undo every edit of `owner`: its welds off, the model's arrays recomputed."""
        edits = self._by_owner.pop(owner, None)
        if edits is None:
            return
        d = self.physics.data.ptr
        for eq in edits.welds:
            d.eq_active[eq] = 0
        self._apply()

    def _apply(self) -> None:
        m = self.physics.model.ptr
        contype, conaffinity = self._contype.copy(), self._conaffinity.copy()
        damping = self._damping.copy()
        object_dof = self.physics.object_dof
        for edits in self._by_owner.values():
            for row in edits.lifted:
                damping[object_dof[row]] = 0.0
            for geom in edits.intangible:
                contype[geom] = conaffinity[geom] = 0
            for geom, bit in edits.ignored:
                conaffinity[geom] &= ~bit
        m.geom_contype[:] = contype
        m.geom_conaffinity[:] = conaffinity
        m.dof_damping[:] = damping
