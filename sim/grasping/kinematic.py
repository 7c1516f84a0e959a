"""The study's kinematic rules (docs/protocol.md §5, §6; the catch rule departs, §11) over a
whole movement at once: the arm follows its targets exactly and objects move only when held or
carried, so a movement is geometry. The hand's path is the forward kinematics of the 50
targets, a rule fires at the first step at which a distance drops below its threshold, and held
objects follow the hand (or the held stick's tip) from that step on; the arm's rules run
compiled (kinematic_kernel.py). tests/sim/stepped_oracle.py writes the same rules one control
step at a time, as the study states them, and tests/sim/test_kinematic_paths.py holds this
closed form to that oracle on thousands of commands, sample by sample and event by event.

Under `WorldConfig.arm_dynamics` "servo" (a rung of the contact ladder) the arm is
where the physical model's servos take it while tracking the targets (sim/arm_servo.py), not at
the targets: the rules act on its angles.
"""

from __future__ import annotations

import functools

import numpy as np

from models.layout import N_STEPS, TOYS, TRACKED_OBJECTS
from sim import events as ev
from sim.arm_servo import ArmServo
from sim.config import WorldConfig
from sim.grasping.base import ArmMovement, GraspBackend
from sim.grasping.carrying import Carrying, PlacedCarrying
from sim.kinematics import hand_positions
from sim.model_edits import ModelEdits
from sim.movement import (
    ARM,
    NOTHING_HELD,
    Brought,
    Holds,
    Movement,
    MovementOutcome,
    MovementTrace,
)
from sim.mujoco_import import mujoco
from sim.physics import PlayroomPhysics


class KinematicPhysics(PlayroomPhysics):
    """The study's kinematic world: a step only recomputes positions.

    The grasp rules set joint and object positions directly; no dynamics run. The hand is where
    the study's analytic forward kinematics puts it (sim/kinematics.py): the same numbers as the
    closed form below, to the last bit. MuJoCo's own hand site agrees with it within 1e-15 m and
    is what renders.
    """

    def step(self, nstep: int = 1) -> None:
        mujoco.mj_kinematics(self._mj_model, self._mj_data)

    def advance(self, nstep: int) -> None:
        self.step(nstep)

    def hand_position(self) -> np.ndarray:
        # Between movements the arm rests: the last angles' answer is kept (tens of
        # microseconds of small array operations saved at every read).
        angles = self.arm_angles()
        key = angles.tobytes()
        if getattr(self, "_hand_for", None) != key:
            self._hand = hand_positions(angles[:, None], self.config)[0]
            self._hand_for = key
        return self._hand.copy()

    def tracked_positions(self) -> np.ndarray:
        out = super().tracked_positions()
        out[0] = self.hand_position()
        return out

    def write_tracked_positions(self, out: np.ndarray) -> None:
        out[...] = self.tracked_positions()

    def stick_tip(self) -> np.ndarray:
        """The tip of the stick from its pose, by the same arithmetic as the held stick's."""
        x, y, yaw = self.object_poses()[0]
        return np.array([x, y]) + self.config.stick_length * np.array([np.cos(yaw), np.sin(yaw)])


class KinematicGrasp(GraspBackend):
    """The arm follows its targets exactly (or its servos', `arm_dynamics` "servo") and objects
    attach by distance. Held objects are placed, not simulated."""

    name = "kinematic"
    physics_class = KinematicPhysics
    solid = False
    closed_form = True

    carrying_class = PlacedCarrying

    def __init__(
        self, config: WorldConfig, edits: ModelEdits, carrying: Carrying, rule: None = None
    ) -> None:
        super().__init__(config, edits, carrying, rule)
        # The servo-driven arm under arm_dynamics "servo"; None: the arm is set to its targets.
        self._servo = ArmServo() if config.arm_dynamics == "servo" else None

    def release(self, physics: PlayroomPhysics) -> None:
        # The arm never left rest: the closed form computes the hand's path without moving it.
        self.hand_holds = None
        self.stick_holds = None

    def after_placements(self, physics: PlayroomPhysics) -> None:
        """Positions are all the closed form reads: the full mj_forward (contacts, constraints,
        forces: 5 times the cost) would compute nothing it uses."""
        mujoco.mj_kinematics(physics.model.ptr, physics.data.ptr)

    # A movement, whole ----------------------------------------------------------------------
    def simulate(
        self, physics: PlayroomPhysics, movement: Movement, trace: MovementTrace | None
    ) -> MovementOutcome:
        """`GraspBackend.simulate` in closed form; MuJoCo's state is set once, at the end."""
        positions = np.empty((N_STEPS + 1, len(TRACKED_OBJECTS), 2))
        positions[0] = movement.start
        brought = movement.brought
        poses = physics.object_poses()
        events: list[ev.Event] = []
        holds = NOTHING_HELD
        still = False
        arm = None
        if movement.space == ARM:
            # (3, N_STEPS), C-ordered as the compiled rules were compiled for (no copy: the
            # targets were made so, then transposed)
            targets = np.ascontiguousarray(movement.controls.T)
            arm = self.arm_movement(targets, poses[0], poses[1:, :2])
            positions[1:], events, holds = arm.positions, arm.events, arm.holds
        else:
            positions[1:] = positions[0]
            if self.voice_grasp(positions[0, 0], poses[0]):  # the study's rule
                events.append(ev.Event(ev.STICK_GRASPED, 1, obj="stick", by="hand"))
                positions[1:, 1] = positions[0, 0]
                holds = Holds("stick", None)
            else:
                still = brought is None
            if brought is not None:
                positions[1:, 2 + brought.toy] = brought.path
        if trace is not None:
            self._trace(physics, trace, positions, events, arm, brought)
        if arm is not None:
            poses[0] = arm.stick_pose
        elif holds.hand == "stick":  # taken by the resting hand, along the last segment
            poses[0] = (*positions[0, 0], self.config.arm_rest_offset)
        poses[1:, :2] = positions[-1, 2:]
        physics.set_object_poses(poses)
        self.hand_holds, self.stick_holds = holds
        return MovementOutcome(positions, movement.sound, events, holds, still)

    def _trace(
        self,
        physics: PlayroomPhysics,
        trace: MovementTrace,
        positions: np.ndarray,
        events: list[ev.Event],
        arm: ArmMovement | None,
        brought: Brought | None,
    ) -> None:
        """Rows 1..N_STEPS of `trace` (its rows all the room before the movement) from the
        movement's positions: the joints where the arm went, the handle and the toys where the
        positions put them, a held stick along the last segment, as the stepped rules place
        them (tests/sim/stepped_oracle.py)."""
        qpos = trace.qpos[1:]
        stick_x, stick_y, stick_yaw = physics.object_qpos[0]
        taken = next((e.step for e in events if e.kind == ev.STICK_GRASPED), None)
        if taken is not None:  # the handle in the hand from that step on
            rows = slice(taken - 1, None)
            qpos[rows, stick_x], qpos[rows, stick_y] = positions[taken:, 1].T
            held_yaw = self.config.arm_rest_offset if arm is None else arm.absolute[-1, rows]
            qpos[rows, stick_yaw] = held_yaw
        # An arm movement's toys are where its positions say (an unmoved toy's are its own
        # joints', copied); during a vocal one only the toy she brings moves.
        toys = range(len(TOYS)) if arm is not None else [] if brought is None else [brought.toy]
        for toy in toys:
            x, y, _ = physics.object_qpos[1 + toy]
            qpos[:, x], qpos[:, y] = positions[1:, 2 + toy].T
        if arm is not None:
            qpos[:, physics.arm_qpos] = arm.angles.T

    def arm_movement(
        self, joint_targets: np.ndarray, stick_pose: np.ndarray, toys: np.ndarray
    ) -> ArmMovement:
        # The compiled rules load numba: imported at the first movement, not with the package.
        from sim.grasping import kinematic_kernel as kernel

        config = self.config
        # The arm's joint angles after each step: its targets, or where its servos take it
        # (`ArmServo.path`: from rest, one servo step a control step).
        angles = joint_targets if self._servo is None else self._servo.path(joint_targets)
        # sim/kinematics.hand_positions' angles, cosines and sines; the rules themselves run
        # compiled (sim/grasping/kinematic_kernel.py), with the same arithmetic.
        absolute = angles.cumsum(axis=0) + config.arm_rest_offset  # (3, N_STEPS)
        cos, sin = np.cos(absolute), np.sin(absolute)
        study_catch = config.catch_rule == "study"
        lying_tip = stick_pose[:2]  # read by the kernel only under the study's catch rule
        if study_catch:
            yaw = stick_pose[2]
            lying_tip = lying_tip + config.stick_length * np.array([np.cos(yaw), np.sin(yaw)])
        positions = np.empty((N_STEPS, 2 + len(TOYS), 2))
        answers = np.empty(5, dtype=np.int64)
        kernel.arm_movement_rules(
            cos,
            sin,
            self._lengths,
            stick_pose,
            toys,
            lying_tip,
            study_catch,
            self._distances,
            positions,
            answers,
        )
        k, first, on_stick, caught_step, caught_toy = answers.tolist()
        path = (angles, absolute)
        events: list[ev.Event] = []
        if on_stick != kernel.NONE:
            events.append(ev.Event(ev.TOY_CAUGHT, 1, obj=TOYS[on_stick], by="stick"))
        final_stick = np.array(stick_pose, dtype=float)
        # A toy the lying stick caught stays on it; only a free stick catches in the hand.
        on_tip = None if on_stick == kernel.NONE else on_stick
        if k == N_STEPS:
            return ArmMovement(positions, final_stick, events, Holds(None, on_tip), *path)
        if first > 0:
            toy = TOYS[first - 1]
            events.insert(0, ev.Event(ev.TOY_GRASPED, k + 1, obj=toy, by="hand"))
            return ArmMovement(
                positions, final_stick, _in_step_order(events), Holds(toy, on_tip), *path
            )
        events.append(ev.Event(ev.STICK_GRASPED, k + 1, obj="stick", by="hand"))
        final_stick = np.array([*positions[-1, 0], absolute[-1, -1]])
        if caught_toy != kernel.NONE:
            obj = TOYS[caught_toy]
            events.append(ev.Event(ev.TOY_CAUGHT, caught_step + 1, obj=obj, by="stick"))
            on_tip = caught_toy
        holds = Holds("stick", on_tip)
        return ArmMovement(positions, final_stick, _in_step_order(events), holds, *path)

    @functools.cached_property
    def _lengths(self) -> np.ndarray:
        """(3,) the segment lengths."""
        return np.asarray(self.config.segment_lengths, dtype=float)

    @functools.cached_property
    def _distances(self) -> np.ndarray:
        """(grasp, catch, stick length) for the kernel."""
        cfg = self.config
        return np.array([cfg.grasp_distance, cfg.catch_distance, cfg.stick_length])

    # Vocal movements: the resting hand's grab -----------------------------------------------
    def voice_grasp(self, hand: np.ndarray, stick_pose: np.ndarray) -> bool:
        """With the study's catch rule, whether the handle lies within the grasp distance."""
        if self.config.catch_rule != "study":
            return False
        return bool(np.hypot(*(stick_pose[:2] - hand)) < self.config.grasp_distance)

    # The experimenter ---------------------------------------------------------------------
    def stick_out_of_reach(self, physics: PlayroomPhysics) -> bool:
        """The handle lies beyond the arm's length plus the grasp distance."""
        cfg = self.config
        return float(np.hypot(*physics.stick_handle())) > cfg.arm_length + cfg.grasp_distance

    def reach(self) -> float:
        """The arm's length plus the grasp distance: `stick_out_of_reach`'s limit."""
        return self.config.arm_length + self.config.grasp_distance


def _in_step_order(events: list[ev.Event]) -> list[ev.Event]:
    """Events by step; within a step, the hand's grasp before the stick's catch."""
    order = {ev.STICK_GRASPED: 0, ev.TOY_GRASPED: 0, ev.TOY_CAUGHT: 1}
    return sorted(events, key=lambda e: (e.step, order[e.kind]))
