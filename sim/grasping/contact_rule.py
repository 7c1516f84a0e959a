"""The physical backend's grasp rule (docs/protocol.md §11 D16): the hand takes the stick when it
touches the handle geom, or a toy when it touches it; the stick's tip catches a toy it touches
while the hand holds the stick. What is taken is held by a weld equality holding the current
relative pose, lifted off the table and no longer colliding with its holder. The touches are
read from the model's contact sensors (`PlayroomPhysics.grasp_contacts`, GRASP_CONTACTS).

Under `WorldConfig.held_pose` "aligned" (a rung of the contact ladder) what is taken
is first placed where the kinematic rules hold it (sim/grasping/kinematic.py): the stick's
handle at the hand, the stick along the last segment; a toy at the hand, or at the held stick's
tip; the weld then holds that pose.
"""

from __future__ import annotations

import numpy as np

from models.layout import TOYS
from sim import events as ev
from sim.config import WorldConfig
from sim.model_edits import ModelEdits
from sim.movement import Holds
from sim.mujoco_import import mujoco
from sim.physics import OBJECTS, PlayroomPhysics

# Where GRASP_CONTACTS (sim/physics.py) holds each kind of contact.
HAND_ON_HANDLE = 0
HAND_ON_TOYS = slice(1, 1 + len(TOYS))
TIP_ON_TOYS = slice(1 + len(TOYS), 1 + 2 * len(TOYS))
_WATCHED_BY_EMPTY_HAND = np.arange(TIP_ON_TOYS.start)
_WATCHED_BY_EMPTY_TIP = np.arange(TIP_ON_TOYS.start, TIP_ON_TOYS.stop)
WATCHED_BY_NOTHING = np.empty(0, dtype=np.int64)


class ContactRule:
    """What a touch takes, given what is held: a function of the holds, whose welds and
    collision edits go through `edits` under the name `owner`."""

    def __init__(self, config: WorldConfig, edits: ModelEdits, owner: str) -> None:
        self.config = config
        self.edits = edits
        self.owner = owner

    def watched(self, holds: Holds) -> np.ndarray:
        """Indices into GRASP_CONTACTS (sim/physics.py) of the contacts that would take
        something now: with the hand empty, the hand on the handle or on a toy; with the stick
        in the hand and nothing on its tip, the tip on a toy; otherwise none. (In both first
        cases every toy is free: nothing else holds one.)"""
        if holds.hand is None:
            return _WATCHED_BY_EMPTY_HAND
        if holds.hand == "stick" and holds.stick is None:
            return _WATCHED_BY_EMPTY_TIP
        return WATCHED_BY_NOTHING

    def take(
        self, physics: PlayroomPhysics, holds: Holds, step: int
    ) -> tuple[Holds, list[ev.Event]]:
        """After control step `step` (1-based): what the watched contacts take, from `holds`;
        the holds after it and the events."""
        watched = self.watched(holds)
        if watched.size == 0:
            return holds, []
        found = physics.grasp_contacts() > 0
        if not found[watched].any():
            return holds, []
        # Wherever a contact is watched every toy is free (`watched`).
        hand, stick = holds
        events: list[ev.Event] = []
        if hand is None:
            toys = found[HAND_ON_TOYS]
            if found[HAND_ON_HANDLE]:
                hand = "stick"
                self._hold(physics, "hand_stick", "stick")
                events.append(ev.Event(ev.STICK_GRASPED, step, obj="stick", by="hand"))
                if self.config.held_pose == "aligned":  # the tip is where the stick now lies
                    found = physics.grasp_contacts() > 0
            elif toys.any():
                toy = TOYS[int(np.argmax(toys))]
                hand = toy
                self._hold(physics, f"hand_{toy}", toy)
                events.append(ev.Event(ev.TOY_GRASPED, step, obj=toy, by="hand"))
        # A stick lying on the table catches nothing: only a stick in the hand is a tool. (The
        # hand may have taken it in this very step: its tip then catches in this step too.)
        if hand == "stick" and stick is None:
            toys = found[TIP_ON_TOYS]
            if toys.any():
                stick = int(np.argmax(toys))
                toy = TOYS[stick]
                self._hold(physics, f"stick_{toy}", toy)
                events.append(ev.Event(ev.TOY_CAUGHT, step, obj=toy, by="stick"))
        return Holds(hand, stick), events

    def _hold(self, physics: PlayroomPhysics, weld: str, obj: str) -> None:
        """Weld `obj` where it is to its holder, lift it off the table (no table friction while
        carried), and stop it colliding with its holder (and only with it).

        MuJoCo makes a contact when one geom's contype meets the other's conaffinity, so a
        holder and its object each lose the other's bit from their conaffinity.
        """
        holder = weld.split("_")[0]
        if self.config.held_pose == "aligned":
            _place_as_the_rules_hold(physics, holder, obj)
        self.edits.weld_here(self.owner, weld)
        self.edits.lift(self.owner, OBJECTS.index(obj))
        holder_geoms = [physics.hand_geom] if holder == "hand" else list(physics.stick_geoms)
        object_geoms = (
            list(physics.stick_geoms) if obj == "stick" else [physics.toy_geoms[TOYS.index(obj)]]
        )
        # The collision bit of a kind of geom is its contype in the MJCF model.
        holder_bit = self.edits.compiled_contype(holder_geoms[0])
        object_bit = self.edits.compiled_contype(object_geoms[0])
        for geom in holder_geoms:
            self.edits.ignore(self.owner, geom, object_bit)
        for geom in object_geoms:
            self.edits.ignore(self.owner, geom, holder_bit)
        if self.config.held_pose == "aligned":
            # Everything the next physics step starts from, computed for the room as it is now
            # (the object moved, the weld on, its collisions edited): without it that step
            # would integrate contact forces found with the object where the touch left it.
            mujoco.mj_forward(physics.model.ptr, physics.data.ptr)


def _place_as_the_rules_hold(physics: PlayroomPhysics, holder: str, obj: str) -> None:
    """Put `obj` where the kinematic rules hold what `holder` ("hand" or "stick") takes: the
    stick's handle at the hand, pointing along the last segment; a toy at the hand or at the
    stick's tip, its yaw kept. Still, with the positions updated (the weld reads them)."""
    row = OBJECTS.index(obj)
    place = physics.hand_position() if holder == "hand" else physics.stick_tip()
    d = physics.data.ptr
    qpos, dof = physics.object_qpos[row], physics.object_dof[row]
    d.qpos[qpos[:2]] = place
    if obj == "stick":
        d.qpos[qpos[2]] = physics.hand_angle()
    d.qvel[dof] = 0.0
    mujoco.mj_kinematics(physics.model.ptr, d)
