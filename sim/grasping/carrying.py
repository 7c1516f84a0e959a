"""How the caregiver carries a toy she brings, one part per kind of world: what she takes
before the movement and how she puts it down after it (sim/caregiver.py asks; where the toy is
at each step is her path, `brought_path`, which each backend's `simulate` follows).

- `PlacedCarrying` (the kinematic backend's, as in the study): nothing is taken, the toy itself
  is placed along her path; nothing to put down.
- `WeldedCarrying` (the physical backend's): her hand, a mocap body, goes to the toy and a weld
  holds it there; she lifts it (it touches nothing while carried, as a toy carried above the
  table would not); putting it down undoes that and brings her hand back beside her.
- `LiftedPlacedCarrying` (the physical backend's under `WorldConfig.caregiver_carrying`
  "placed", a part of the contact step unbundled): the toy itself put at each step of her path,
  as the kinematic rules place it, lifted and touching nothing while carried as the welded toy
  is: only the weld's dynamics differ.

Each says what her path moves (`moves`): the two numbers each control step of a physical
movement sets to the path's next point (sim/physics.py `control_steps`).
"""

from __future__ import annotations

from typing import Protocol

import numpy as np

from models.layout import TOYS
from sim.model_edits import ModelEdits
from sim.mujoco_import import mujoco
from sim.physics import OBJECTS, PlayroomPhysics

# The name under which the caregiver's carrying edits the model (sim/model_edits.py); the
# grasps edit it under their backend's name.
CAREGIVER = "caregiver"


class Carrying(Protocol):
    """What the caregiver does with a toy she brings, besides following her path."""

    def takes(self, physics: PlayroomPhysics, toy: int) -> np.ndarray:
        """She takes toy `toy` (0-based) to bring it over the coming control steps. Returns
        (2,) where what she moves starts: her path begins there."""
        ...

    def puts_down(self, physics: PlayroomPhysics) -> None:
        """She puts the toy down where it is."""
        ...

    def moves(self, physics: PlayroomPhysics, toy: int) -> np.ndarray:
        """What her path moves while she brings toy `toy`: a view of the data whose first two
        numbers are its x, y."""
        ...


def _toy_xy(physics: PlayroomPhysics, toy: int) -> np.ndarray:
    """A view of the data's qpos holding toy `toy`'s x, y (its slide joints, consecutive)."""
    x, y, _ = physics.object_qpos[1 + toy]
    if y != x + 1:
        raise ValueError("the MJCF model's toy joints are not x, y, yaw in this order")
    return physics.data.ptr.qpos[x : x + 2]


class PlacedCarrying:
    """The toy itself is placed at every step of her path, as in the study."""

    def __init__(self, edits: ModelEdits | None = None) -> None:
        """Built as every carrying is (sim/grasping/base.py); it edits nothing of the model."""

    def takes(self, physics: PlayroomPhysics, toy: int) -> np.ndarray:
        """Nothing to take: the path starts where the toy lies."""
        return physics.object_poses()[1 + toy, :2]

    def puts_down(self, physics: PlayroomPhysics) -> None:
        """Nothing to undo: the toy lies where it was last placed."""

    def moves(self, physics: PlayroomPhysics, toy: int) -> np.ndarray:
        """The toy itself."""
        return _toy_xy(physics, toy)


class WeldedCarrying:
    """Her hand, welded to the toy, carries it through the dynamics, lifted off the table."""

    def __init__(self, edits: ModelEdits) -> None:
        self.edits = edits

    def takes(self, physics: PlayroomPhysics, toy: int) -> np.ndarray:
        """Her hand goes to the toy and takes it; her path starts there."""
        m, d = physics.model.ptr, physics.data.ptr
        hand = physics.caregiver_hand_mocap
        d.mocap_pos[hand, :2] = physics.toy_positions()[toy]
        mujoco.mj_kinematics(m, d)
        # Her hand sits on the toy: the weld holds it there, upright.
        self.edits.weld_here(CAREGIVER, f"caregiver_{TOYS[toy]}", keep_orientation=False)
        # She lifts the toy: while carried it touches nothing, as a toy carried above the
        # table would not (dragged along the table it would sweep the stick out of reach).
        self.edits.make_intangible(CAREGIVER, physics.toy_geoms[toy])
        self.edits.lift(CAREGIVER, OBJECTS.index(TOYS[toy]))
        return d.mocap_pos[hand, :2].copy()

    def puts_down(self, physics: PlayroomPhysics) -> None:
        self.edits.clear(CAREGIVER)
        d = physics.data.ptr
        physics.stop_objects()
        d.mocap_pos[physics.caregiver_hand_mocap, :2] = physics.caregiver_position()

    def moves(self, physics: PlayroomPhysics, toy: int) -> np.ndarray:
        """Her hand (its mocap position), which the weld follows."""
        return physics.data.ptr.mocap_pos[physics.caregiver_hand_mocap]


class LiftedPlacedCarrying:
    """The toy placed at every step of her path, lifted off the table, touching nothing."""

    def __init__(self, edits: ModelEdits) -> None:
        self.edits = edits

    def takes(self, physics: PlayroomPhysics, toy: int) -> np.ndarray:
        """She lifts the toy where it lies (as the welded carrying does, without her hand):
        her path starts there."""
        self.edits.make_intangible(CAREGIVER, physics.toy_geoms[toy])
        self.edits.lift(CAREGIVER, OBJECTS.index(TOYS[toy]))
        return physics.toy_positions()[toy].copy()

    def puts_down(self, physics: PlayroomPhysics) -> None:
        self.edits.clear(CAREGIVER)
        physics.stop_objects()

    def moves(self, physics: PlayroomPhysics, toy: int) -> np.ndarray:
        """The toy itself (its joints' x, y), still between steps: nothing touches it."""
        return _toy_xy(physics, toy)
