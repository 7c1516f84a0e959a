"""Grasping through MuJoCo contacts (docs/protocol.md §11 D16), the physical backend: position
servos track the arm's targets through the dynamics, every object a solid body pushed by
whatever touches it; a movement's control steps run compiled (sim/compiled_steps.py), returning
here when a contact its grasp rule acts on appears. Its parts, which the playroom
builds and hands it: the grasp rule (sim/grasping/contact_rule.py: what a touch takes, held by
welds) and the caregiver's carrying (sim/grasping/carrying.py: her hand welded to the toy,
lifted above the table; or, under `WorldConfig.caregiver_carrying` "placed", the lifted toy
put on her path).
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from models.layout import N_JOINTS, N_STEPS, TRACKED_OBJECTS
from sim import events as ev
from sim.compiled_steps import AVAILABLE, MISSING
from sim.config import SETTLE_PHYSICS_STEPS, WorldConfig
from sim.grasping.base import GraspBackend, arm_to_rest
from sim.grasping.carrying import Carrying, LiftedPlacedCarrying, WeldedCarrying
from sim.grasping.contact_rule import WATCHED_BY_NOTHING, ContactRule
from sim.kinematics import segment_distance
from sim.model_edits import ModelEdits
from sim.movement import ARM, NOTHING_HELD, Movement, MovementOutcome, MovementTrace
from sim.mujoco_import import mujoco
from sim.physics import PlayroomPhysics

_NO_TARGETS = np.empty((0, N_JOINTS))


class PhysicalGrasp(GraspBackend):
    """Grasps by contact, held by welds; every object a solid body."""

    name = "physical"
    physics_class = PlayroomPhysics
    carrying_class = WeldedCarrying
    rule_class = ContactRule

    @classmethod
    def carrying_for(cls, config: WorldConfig) -> Callable[[ModelEdits], Carrying]:
        """Welded, or the toy placed on her path (`WorldConfig.caregiver_carrying`)."""
        return LiftedPlacedCarrying if config.caregiver_carrying == "placed" else WeldedCarrying

    solid = True
    closed_form = False
    rule: ContactRule

    def __init__(
        self, config: WorldConfig, edits: ModelEdits, carrying: Carrying, rule: ContactRule
    ) -> None:
        if not AVAILABLE:
            raise RuntimeError(MISSING)
        super().__init__(config, edits, carrying, rule)
        self._before: np.ndarray | None = None  # the state `begin` saved

    def begin(self, physics: PlayroomPhysics) -> None:
        super().begin(physics)
        # Only the physics changes during the steps: what a divergence puts back.
        self._before = physics.integration_state()

    # A movement, stepped in compiled code -------------------------------------------------
    def simulate(
        self, physics: PlayroomPhysics, movement: Movement, trace: MovementTrace | None
    ) -> MovementOutcome:
        """`GraspBackend.simulate`: the control steps in compiled code (sim/compiled_steps.py)
        between the contacts the grasp acts on (`_take_by_contact`, here in Python). A movement
        whose physics diverges (MuJoCo warns, or a position is not finite) leaves the room where
        it was: `diverged_from` is the state `begin` saved."""
        positions = np.empty((N_STEPS + 1, len(TRACKED_OBJECTS), 2))
        positions[0] = movement.start
        grasping = movement.space == ARM
        # The servos' targets; a vocal movement leaves them at rest.
        targets = np.ascontiguousarray(movement.controls) if grasping else _NO_TARGETS
        brought = movement.brought
        path = None if brought is None else brought.path
        moved = None if brought is None else self.carrying.moves(physics, brought.toy)
        warnings = physics.warning_counts()
        events: list[ev.Event] = []

        def steps_from(k: int) -> int:
            watched = self.watched_contacts() if grasping else WATCHED_BY_NOTHING
            return physics.control_steps(k, targets, path, positions, watched, trace, moved)

        k = steps_from(0)
        while k < N_STEPS:  # a contact the grasp acts on, after step k
            events += self._take_by_contact(physics, k + 1)
            physics.write_tracked_positions(positions[k + 1])  # as the grasp left them
            if trace is not None:
                trace.record(k + 1, physics.data.ptr)
            k = steps_from(k + 1)
        if (physics.warning_counts() > warnings).any() or not np.isfinite(positions).all():
            positions[1:] = positions[0]  # the room goes on from where it was
            if trace is not None:
                trace.qpos[1:], trace.mocap_pos[1:] = trace.qpos[0], trace.mocap_pos[0]
            sound, before = movement.sound, self._before
            return MovementOutcome(positions, sound, [], NOTHING_HELD, diverged_from=before)
        return MovementOutcome(positions, movement.sound, events, self.holds)

    def watched_contacts(self) -> np.ndarray:
        """The contacts that would take something now (`ContactRule.watched`)."""
        return self.rule.watched(self.holds)

    def _take_by_contact(self, physics: PlayroomPhysics, step: int) -> list[ev.Event]:
        """After control step `step` (1-based): what the watched contacts take."""
        holds, events = self.rule.take(physics, self.holds, step)
        self.hand_holds, self.stick_holds = holds
        return events

    def release(self, physics: PlayroomPhysics) -> None:
        self.hand_holds = None
        self.stick_holds = None
        self.edits.clear(self.name)
        physics.stop_objects()
        arm_to_rest(physics)

    def after_placements(self, physics: PlayroomPhysics) -> None:
        """Everything the next movement's first step starts from: contacts, constraints and
        forces, computed for the room as the placements left it."""
        mujoco.mj_forward(physics.model.ptr, physics.data.ptr)

    def settle(self, physics: PlayroomPhysics) -> None:
        """With `settle_between_movements` (an ablation): the room's physics runs
        SETTLE_PHYSICS_STEPS with the arm held at rest before the next movement, so that
        objects a release, the arm's return to rest or the caregiver's putting down left
        overlapping part now, and not during the next movement, where a vocal movement would
        record their parting as its toy's outcome. Then everything is still again."""
        if not self.config.settle_between_movements:
            return
        # `advance` begins with mj_step2, which integrates the forces mj_step1 computed last:
        # those of the held, welded state before the release and the arm's return to rest.
        # Computed again for the room as it is now, as a movement's start computes them
        # (sim/playroom.py's placements end in mj_forward); without it the stale contact
        # forces flung the stick up to 0.9 m in a settle (the first settle ablation run).
        mujoco.mj_forward(physics.model.ptr, physics.data.ptr)
        physics.advance(SETTLE_PHYSICS_STEPS)
        physics.stop_objects()
        arm_to_rest(physics)

    # The experimenter ---------------------------------------------------------------------
    def stick_out_of_reach(self, physics: PlayroomPhysics) -> bool:
        """No point of the handle geom lies within the arm's length plus the radii of the hand
        sphere and of the handle: contact is impossible; or, with `stick_return_reach` set, the
        handle lies farther than it from the base (docs/protocol.md D14: where the learning arm
        stops grasping, nearer than where contact stops being possible)."""
        reach = self.config.stick_return_reach
        if reach is not None and np.hypot(*physics.stick_handle()) > reach:
            return True
        m, d = physics.model.ptr, physics.data.ptr
        handle = physics.handle_geom
        centre = d.geom_xpos[handle, :2]
        contact = m.geom_size[physics.hand_geom, 0] + m.geom_size[handle, 0]
        limit = self.config.arm_length + contact
        # The handle's centre is a point of it: if that lies within the limit, so does the
        # nearest point (the margin covers rounding). Most iterations end here.
        if np.hypot(centre[0], centre[1]) < limit - 1e-9:
            return False
        axis = d.geom_xmat[handle].reshape(3, 3)[:2, 2]  # a capsule's axis is its local z
        half = m.geom_size[handle, 1]
        nearest = segment_distance(np.zeros(2), centre - half * axis, centre + half * axis)
        return nearest > limit

    def reach(self) -> float:
        """The arm's length plus the radii of the hand sphere and of the handle: beyond it no
        point of the handle can touch the hand (`stick_out_of_reach`'s contact limit)."""
        physics = self.edits.physics
        sizes = physics.model.ptr.geom_size
        contact = sizes[physics.hand_geom, 0] + sizes[physics.handle_geom, 0]
        return float(self.config.arm_length + contact)
