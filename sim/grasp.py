"""The two grasp backends: the study's distance rules, and grasping through MuJoCo contacts.

Both share one MJCF model and one interface. Per control step the task calls
`before_step(physics, joint_targets, step)`, then the physics steps, then
`after_step(physics, step)`; both return the events of that step. `release(physics)` ends a
movement: everything held is dropped where it is and the arm goes back to rest.
"""

from __future__ import annotations

import abc

import mujoco
import numpy as np

from sim import events as ev
from sim.config import WorldConfig
from sim.model_edits import ModelEdits
from sim.physics import OBJECTS, TOYS, PlayroomPhysics


class GraspBackend(abc.ABC):
    """What the hand holds and what the stick's tip holds, and how that changes."""

    name: str

    def __init__(self, config: WorldConfig) -> None:
        self.config = config
        self.hand_holds: str | None = None  # "stick", "toy1", ... or None
        self.stick_holds: int | None = None  # index of the toy on the stick's tip

    def begin(self, physics: PlayroomPhysics) -> None:
        """Start of a movement: nothing is held."""
        self.hand_holds = None
        self.stick_holds = None

    @abc.abstractmethod
    def before_step(
        self, physics: PlayroomPhysics, joint_targets: np.ndarray, step: int
    ) -> list[ev.Event]:
        """Drive the arm toward joint_targets (3,) rad, relative to rest."""

    @abc.abstractmethod
    def after_step(self, physics: PlayroomPhysics, step: int) -> list[ev.Event]:
        """Look at the world after the step and attach what the rules say."""

    def during_voice(self, physics: PlayroomPhysics, step: int) -> list[ev.Event]:
        """A control step of a vocal movement, the arm at rest: nothing is grasped."""
        return []

    @abc.abstractmethod
    def release(self, physics: PlayroomPhysics) -> None:
        """Drop everything where it is and put the arm back at rest."""

    def _free_toy_mask(self) -> np.ndarray:
        """(3,) bool: toys that neither the hand nor the stick holds."""
        free = np.ones(len(TOYS), dtype=bool)
        if self.stick_holds is not None:
            free[self.stick_holds] = False
        if self.hand_holds in TOYS:
            free[TOYS.index(self.hand_holds)] = False
        return free


def _arm_to_rest(physics: PlayroomPhysics) -> None:
    d = physics.data.ptr
    d.qpos[physics.arm_qpos] = 0.0
    d.qvel[physics.arm_dof] = 0.0
    d.ctrl[:] = 0.0
    mujoco.mj_kinematics(physics.model.ptr, d)


class KinematicGrasp(GraspBackend):
    """The study's rules (docs/protocol.md §5; the catch rule departs, §11): the arm follows its
    targets exactly and objects attach by distance. Held objects are placed, not simulated."""

    name = "kinematic"

    def before_step(
        self, physics: PlayroomPhysics, joint_targets: np.ndarray, step: int
    ) -> list[ev.Event]:
        d = physics.data.ptr
        d.qpos[physics.arm_qpos] = joint_targets
        mujoco.mj_kinematics(physics.model.ptr, d)
        events = self._attach_by_distance(physics, step)
        self._carry(physics)
        return events

    def after_step(self, physics: PlayroomPhysics, step: int) -> list[ev.Event]:
        return []

    def during_voice(self, physics: PlayroomPhysics, step: int) -> list[ev.Event]:
        """With the study's catch rule, the resting hand takes a stick whose handle lies
        within the grasp distance (the study's code checks it in vocal movements too)."""
        if self.config.catch_rule != "study" or self.hand_holds is not None:
            return []
        positions = physics.tracked_positions()
        if np.hypot(*(positions[1] - positions[0])) >= self.config.grasp_distance:
            return []
        self.hand_holds = "stick"
        self._carry(physics)
        return [ev.Event(ev.STICK_GRASPED, step, obj="stick", by="hand")]

    def _attach_by_distance(self, physics: PlayroomPhysics, step: int) -> list[ev.Event]:
        """The study's rules: a free hand takes the stick, else the first toy within reach; the
        stick's tip catches the first free toy within reach if it holds none: a held stick's
        only (catch_rule "held_stick"), or the stick wherever it is ("study")."""
        cfg = self.config
        events: list[ev.Event] = []
        positions = physics.tracked_positions()  # hand, handle, toy1-3
        free = self._free_toy_mask()
        if self.hand_holds is None:
            near = np.hypot(*(positions[1:] - positions[0]).T) < cfg.grasp_distance
            near[1:] &= free
            if near.any():
                first = int(np.argmax(near))
                if first == 0:
                    self.hand_holds = "stick"
                    events.append(ev.Event(ev.STICK_GRASPED, step, obj="stick", by="hand"))
                else:
                    self.hand_holds = TOYS[first - 1]
                    free[first - 1] = False
                    events.append(ev.Event(ev.TOY_GRASPED, step, obj=TOYS[first - 1], by="hand"))
        held = self.hand_holds == "stick"
        if (held or cfg.catch_rule == "study") and self.stick_holds is None:
            tip = self._held_stick_tip(physics) if held else physics.stick_tip()
            near = (np.hypot(*(positions[2:] - tip).T) < cfg.catch_distance) & free
            if near.any():
                self.stick_holds = int(np.argmax(near))
                events.append(ev.Event(ev.TOY_CAUGHT, step, obj=TOYS[self.stick_holds], by="stick"))
        return events

    def _held_stick_tip(self, physics: PlayroomPhysics) -> np.ndarray:
        """The tip of the stick held by the hand: the handle is at the hand and the stick
        points along the hand's orientation."""
        yaw = physics.hand_angle()
        return physics.hand_position() + self.config.stick_length * np.array(
            [np.cos(yaw), np.sin(yaw)]
        )

    def _carry(self, physics: PlayroomPhysics) -> None:
        """Place held objects: the handle at the hand, toys at the hand or the stick's tip."""
        if self.hand_holds is None:
            if self.stick_holds is not None:  # a toy caught by the lying stick, at its tip
                poses = physics.object_poses()
                poses[1 + self.stick_holds, :2] = physics.stick_tip()
                physics.set_object_poses(poses)
            return
        poses = physics.object_poses()
        if self.hand_holds == "stick":
            poses[0] = (*physics.hand_position(), physics.hand_angle())
            if self.stick_holds is not None:
                poses[1 + self.stick_holds, :2] = self._held_stick_tip(physics)
        else:
            poses[1 + TOYS.index(self.hand_holds), :2] = physics.hand_position()
        physics.set_object_poses(poses)

    def release(self, physics: PlayroomPhysics) -> None:
        self.hand_holds = None
        self.stick_holds = None
        _arm_to_rest(physics)


class PhysicalGrasp(GraspBackend):
    """Grasping through contact: position servos track the targets through the dynamics; the
    hand takes the stick when it touches the handle geom, or a toy when it touches it; the
    stick's tip catches a toy it touches. A grasp activates a weld equality holding the current
    relative pose. Unheld objects are pushed by whatever touches them."""

    name = "physical"

    def __init__(self, config: WorldConfig, edits: ModelEdits) -> None:
        super().__init__(config)
        self.edits = edits

    def before_step(
        self, physics: PlayroomPhysics, joint_targets: np.ndarray, step: int
    ) -> list[ev.Event]:
        physics.data.ptr.ctrl[:] = joint_targets
        return []

    def after_step(self, physics: PlayroomPhysics, step: int) -> list[ev.Event]:
        pairs = physics.touching_pairs()
        if len(pairs) == 0:
            return []
        events: list[ev.Event] = []
        free = self._free_toy_mask()
        if self.hand_holds is None:
            touched = _partners(pairs, physics.hand_geom)
            toys = np.isin(physics.toy_geoms, touched) & free
            if physics.handle_geom in touched:
                self.hand_holds = "stick"
                self._hold(physics, "hand_stick", "stick")
                events.append(ev.Event(ev.STICK_GRASPED, step, obj="stick", by="hand"))
            elif toys.any():
                toy = TOYS[int(np.argmax(toys))]
                self.hand_holds = toy
                free[TOYS.index(toy)] = False
                self._hold(physics, f"hand_{toy}", toy)
                events.append(ev.Event(ev.TOY_GRASPED, step, obj=toy, by="hand"))
        # A stick lying on the table catches nothing: only a stick in the hand is a tool.
        if self.hand_holds == "stick" and self.stick_holds is None:
            toys = np.isin(physics.toy_geoms, _partners(pairs, physics.tip_geom)) & free
            if toys.any():
                self.stick_holds = int(np.argmax(toys))
                toy = TOYS[self.stick_holds]
                self._hold(physics, f"stick_{toy}", toy)
                events.append(ev.Event(ev.TOY_CAUGHT, step, obj=toy, by="stick"))
        return events

    def _hold(self, physics: PlayroomPhysics, weld: str, obj: str) -> None:
        """Weld `obj` where it is to its holder, lift it off the table (no table friction while
        carried), and stop it colliding with its holder (and only with it).

        MuJoCo makes a contact when one geom's contype meets the other's conaffinity, so a
        holder and its object each lose the other's bit from their conaffinity.
        """
        self.edits.weld_here(self.name, weld)
        self.edits.lift(self.name, OBJECTS.index(obj))
        holder = weld.split("_")[0]
        holder_geoms = [physics.hand_geom] if holder == "hand" else list(physics.stick_geoms)
        object_geoms = (
            list(physics.stick_geoms) if obj == "stick" else [physics.toy_geoms[TOYS.index(obj)]]
        )
        # The collision bit of a kind of geom is its contype in the MJCF model.
        holder_bit = self.edits.compiled_contype(holder_geoms[0])
        object_bit = self.edits.compiled_contype(object_geoms[0])
        for geom in holder_geoms:
            self.edits.ignore(self.name, geom, object_bit)
        for geom in object_geoms:
            self.edits.ignore(self.name, geom, holder_bit)

    def release(self, physics: PlayroomPhysics) -> None:
        self.hand_holds = None
        self.stick_holds = None
        self.edits.clear(self.name)
        physics.data.ptr.qvel[physics.object_dof] = 0.0
        _arm_to_rest(physics)


def _partners(pairs: np.ndarray, geom: int) -> np.ndarray:
    """Geoms in contact with `geom`, from (n, 2) contact pairs."""
    return np.concatenate([pairs[pairs[:, 0] == geom, 1], pairs[pairs[:, 1] == geom, 0]])


BACKENDS = ("kinematic", "physical")


def make_backend(name: str, config: WorldConfig, edits: ModelEdits) -> GraspBackend:
    """The grasp backend called `name` ('kinematic' or 'physical'); the physical one edits the
    model through `edits`."""
    if name == "kinematic":
        return KinematicGrasp(config)
    if name == "physical":
        return PhysicalGrasp(config, edits)
    raise ValueError(f"unknown grasp backend {name!r}: choose one of {list(BACKENDS)}")
