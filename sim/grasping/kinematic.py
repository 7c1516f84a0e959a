"""The study's kinematic rules (docs/protocol.md §5, §6; the catch rule departs, §11), each
written twice: stepped, as the dm_control task applies it one control step at a time (the
room's path when step observers watch, as in videos), and in closed form over a whole movement
at once (the room's fast path; the arm's rules compiled in kinematic_kernel.py). The arm
follows its targets exactly and objects move only when held or carried, so a movement is
geometry: the hand's path is the forward kinematics of the 50 targets, a rule fires at the
first step at which a distance drops below its threshold, and held objects follow the hand (or
the held stick's tip) from that step on. tests/sim/test_kinematic_paths.py compares the two
forms on thousands of commands, sample by sample and event by event: change a rule in both
forms, and run it.

Under `WorldConfig.arm_dynamics` "servo" (a rung of the contact ladder) the arm is
where the physical model's servos take it while tracking the targets (sim/arm_servo.py), not at
the targets: both forms read its angles from the same servo steps, and the rules act on them.
"""

from __future__ import annotations

import functools

import mujoco
import numpy as np

from models.layout import N_STEPS, TOYS
from sim import events as ev
from sim.arm_servo import ArmServo
from sim.config import WorldConfig
from sim.grasping.base import ArmMovement, ClosedForm, Holds, arm_to_rest
from sim.kinematics import hand_positions
from sim.model_edits import ModelEdits
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


class KinematicGrasp(ClosedForm):
    """The arm follows its targets exactly (or its servos', `arm_dynamics` "servo") and objects
    attach by distance. Held objects are placed, not simulated."""

    name = "kinematic"
    physics_class = KinematicPhysics
    solid = False
    _arm_moved = False  # whether a stepped movement moved the arm from rest (`release`)

    def __init__(self, config: WorldConfig, edits: ModelEdits) -> None:
        super().__init__(config, edits)
        # The servo-driven arm under arm_dynamics "servo"; None: the arm is set to its targets.
        self._servo = ArmServo() if config.arm_dynamics == "servo" else None

    def begin(self, physics: PlayroomPhysics) -> None:
        super().begin(physics)
        if self._servo is not None:  # every movement starts from rest
            self._servo.reset()

    # Arm movements: the grasp and catch rules, stepped ------------------------------------
    def before_step(
        self, physics: PlayroomPhysics, joint_targets: np.ndarray, step: int
    ) -> list[ev.Event]:
        d = physics.data.ptr
        servo = self._servo
        d.qpos[physics.arm_qpos] = joint_targets if servo is None else servo.step(joint_targets)
        self._arm_moved = True
        mujoco.mj_kinematics(physics.model.ptr, d)
        events = self._attach_by_distance(physics, step)
        self._carry(physics)
        return events

    def after_step(self, physics: PlayroomPhysics, step: int) -> list[ev.Event]:
        return []

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
        # Only the stepped path moves the arm (the closed form computes the hand's path without
        # it, and no dynamics give it a velocity or a control): at rest, it stays as it is.
        if self._arm_moved:
            arm_to_rest(physics)
            self._arm_moved = False

    # Arm movements: the same rules in closed form -----------------------------------------
    def arm_movement(
        self, joint_targets: np.ndarray, stick_pose: np.ndarray, toys: np.ndarray
    ) -> ArmMovement:
        # The compiled rules load numba: imported at the first movement, not with the package.
        from sim.grasping import kinematic_kernel as kernel

        config = self.config
        # The arm's joint angles after each step: its targets, or where its servos take it
        # (the same servo steps as `before_step`'s, from rest).
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
        events: list[ev.Event] = []
        if on_stick != kernel.NONE:
            events.append(ev.Event(ev.TOY_CAUGHT, 1, obj=TOYS[on_stick], by="stick"))
        final_stick = np.array(stick_pose, dtype=float)
        # A toy the lying stick caught stays on it; only a free stick catches in the hand.
        on_tip = None if on_stick == kernel.NONE else on_stick
        if k == N_STEPS:
            return ArmMovement(positions, final_stick, events, Holds(None, on_tip))
        if first > 0:
            toy = TOYS[first - 1]
            events.insert(0, ev.Event(ev.TOY_GRASPED, k + 1, obj=toy, by="hand"))
            return ArmMovement(positions, final_stick, _in_step_order(events), Holds(toy, on_tip))
        events.append(ev.Event(ev.STICK_GRASPED, k + 1, obj="stick", by="hand"))
        final_stick = np.array([*positions[-1, 0], absolute[-1, -1]])
        if caught_toy != kernel.NONE:
            obj = TOYS[caught_toy]
            events.append(ev.Event(ev.TOY_CAUGHT, caught_step + 1, obj=obj, by="stick"))
            on_tip = caught_toy
        return ArmMovement(positions, final_stick, _in_step_order(events), Holds("stick", on_tip))

    @functools.cached_property
    def _lengths(self) -> np.ndarray:
        """(3,) the segment lengths."""
        return np.asarray(self.config.segment_lengths, dtype=float)

    @functools.cached_property
    def _distances(self) -> np.ndarray:
        """(grasp, catch, stick length) for the kernel."""
        cfg = self.config
        return np.array([cfg.grasp_distance, cfg.catch_distance, cfg.stick_length])

    # Vocal movements: the resting hand's grab, stepped and in closed form -----------------
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

    def voice_grasp(self, hand: np.ndarray, stick_pose: np.ndarray) -> bool:
        """With the study's catch rule, whether the handle lies within the grasp distance."""
        if self.config.catch_rule != "study":
            return False
        return bool(np.hypot(*(stick_pose[:2] - hand)) < self.config.grasp_distance)

    # The caregiver bringing a toy: placed directly along her path, as in the study -------
    def caregiver_takes(self, physics: PlayroomPhysics, toy: int) -> np.ndarray:
        """Nothing to take: the toy itself is placed at every step; its path starts where it
        lies."""
        return physics.object_poses()[1 + toy, :2]

    def caregiver_carries(self, physics: PlayroomPhysics, toy: int, place: np.ndarray) -> None:
        poses = physics.object_poses()
        poses[1 + toy, :2] = place
        physics.set_object_poses(poses)

    def caregiver_puts_down(self, physics: PlayroomPhysics) -> None:
        """Nothing to undo: the toy lies where it was last placed."""

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
