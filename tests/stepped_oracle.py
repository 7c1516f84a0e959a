"""The backends' rules one control step at a time, in plain Python: the oracle the fast paths
are held to, bit for bit (tests/sim/test_kinematic_paths.py, tests/sim/test_compiled_steps.py).

The room computes a movement one way per backend (`GraspBackend.simulate`: the kinematic rules
in closed form, compiled; the physical steps in compiled code). Here each rule is written as the
study states it, step by step: the kinematic hand takes the first object within reach at the
first step it comes within reach, and held things follow the hand or the held stick's tip; the
physical servos' targets and the caregiver's hand are set before each control step, the
physics advanced in Python, and the backend's own contact rule applied after it.
`use_oracle(room)` makes a room compute its movements here, so that a twin room with the fast
path can be compared with it.
"""

from __future__ import annotations

import numpy as np

from models.layout import N_STEPS, TOYS, TRACKED_OBJECTS
from sim import Playroom
from sim import events as ev
from sim.arm_servo import ArmServo
from sim.grasping.base import GraspBackend
from sim.movement import ARM, NOTHING_HELD, Movement, MovementOutcome, MovementTrace
from sim.physics import CONTROL_SUBSTEPS, PlayroomPhysics


def use_oracle(room: Playroom) -> Playroom:
    """The room, its movements computed step by step here from now on."""
    backend = room.backend
    servo = ArmServo() if room.config.arm_dynamics == "servo" else None

    def simulate(physics, movement, trace):
        steps = _kinematic_steps if backend.name == "kinematic" else _physical_steps
        return steps(backend, servo, physics, movement, trace)

    backend.simulate = simulate  # type: ignore[method-assign]
    return room


def _kinematic_steps(
    backend: GraspBackend,
    servo: ArmServo | None,
    physics: PlayroomPhysics,
    movement: Movement,
    trace: MovementTrace | None,
) -> MovementOutcome:
    space, controls, start, sound, brought = movement
    positions = _positions_from(start)
    events: list[ev.Event] = []
    d = physics.data.ptr
    if servo is not None:
        servo.reset()
    for k in range(N_STEPS):
        step = k + 1
        if space == ARM:
            targets = controls[k]
            d.qpos[physics.arm_qpos] = targets if servo is None else servo.step(targets)
            physics.advance(1)  # the kinematic physics: positions recomputed
            events += _attach_by_distance(backend, physics, step)
            _carry(backend, physics)
        else:
            events += _resting_hand_takes(backend, physics, step)
        if brought is not None:  # the toy she brings placed on her path
            poses = physics.object_poses()
            poses[1 + brought.toy, :2] = brought.path[k]
            physics.set_object_poses(poses)
        physics.advance(CONTROL_SUBSTEPS)
        physics.write_tracked_positions(positions[step])
        if trace is not None:
            trace.record(step, d)
    physics.rest_arm()
    return MovementOutcome(positions, sound, events, backend.holds)


def _attach_by_distance(
    backend: GraspBackend, physics: PlayroomPhysics, step: int
) -> list[ev.Event]:
    """The study's rules: a free hand takes the stick, else the first toy within reach; the
    stick's tip catches the first free toy within reach if it holds none: a held stick's
    only (catch_rule "held_stick"), or the stick wherever it is ("study")."""
    cfg = backend.config
    events: list[ev.Event] = []
    positions = physics.tracked_positions()  # hand, handle, toy1-3
    free = np.ones(len(TOYS), dtype=bool)
    if backend.stick_holds is not None:
        free[backend.stick_holds] = False
    if backend.hand_holds in TOYS:
        free[TOYS.index(backend.hand_holds)] = False
    if backend.hand_holds is None:
        near = np.hypot(*(positions[1:] - positions[0]).T) < cfg.grasp_distance
        near[1:] &= free
        if near.any():
            first = int(np.argmax(near))
            if first == 0:
                backend.hand_holds = "stick"
                events.append(ev.Event(ev.STICK_GRASPED, step, obj="stick", by="hand"))
            else:
                backend.hand_holds = TOYS[first - 1]
                free[first - 1] = False
                events.append(ev.Event(ev.TOY_GRASPED, step, obj=TOYS[first - 1], by="hand"))
    held = backend.hand_holds == "stick"
    if (held or cfg.catch_rule == "study") and backend.stick_holds is None:
        tip = _held_stick_tip(backend, physics) if held else physics.stick_tip()
        near = (np.hypot(*(positions[2:] - tip).T) < cfg.catch_distance) & free
        if near.any():
            backend.stick_holds = int(np.argmax(near))
            caught = TOYS[backend.stick_holds]
            events.append(ev.Event(ev.TOY_CAUGHT, step, obj=caught, by="stick"))
    return events


def _held_stick_tip(backend: GraspBackend, physics: PlayroomPhysics) -> np.ndarray:
    """The handle at the hand, the stick along the hand's orientation."""
    yaw = physics.hand_angle()
    direction = np.array([np.cos(yaw), np.sin(yaw)])
    return physics.hand_position() + backend.config.stick_length * direction


def _carry(backend: GraspBackend, physics: PlayroomPhysics) -> None:
    """Held objects placed: the handle at the hand, toys at the hand or the stick's tip."""
    poses = physics.object_poses()
    if backend.hand_holds is None:
        if backend.stick_holds is None:
            return
        poses[1 + backend.stick_holds, :2] = physics.stick_tip()  # on the lying stick's tip
    elif backend.hand_holds == "stick":
        poses[0] = (*physics.hand_position(), physics.hand_angle())
        if backend.stick_holds is not None:
            poses[1 + backend.stick_holds, :2] = _held_stick_tip(backend, physics)
    else:
        poses[1 + TOYS.index(backend.hand_holds), :2] = physics.hand_position()
    physics.set_object_poses(poses)


def _resting_hand_takes(
    backend: GraspBackend, physics: PlayroomPhysics, step: int
) -> list[ev.Event]:
    """With the study's catch rule, the resting hand takes a stick whose handle lies within
    the grasp distance, in vocal movements too (the study's code checks it there)."""
    cfg = backend.config
    if cfg.catch_rule != "study" or backend.hand_holds is not None:
        return []
    positions = physics.tracked_positions()
    if np.hypot(*(positions[1] - positions[0])) >= cfg.grasp_distance:
        return []
    backend.hand_holds = "stick"
    _carry(backend, physics)
    return [ev.Event(ev.STICK_GRASPED, step, obj="stick", by="hand")]


def _physical_steps(
    backend: GraspBackend,
    servo: ArmServo | None,
    physics: PlayroomPhysics,
    movement: Movement,
    trace: MovementTrace | None,
) -> MovementOutcome:
    space, controls, start, sound, brought = movement
    positions = _positions_from(start)
    events: list[ev.Event] = []
    d = physics.data.ptr
    warnings = physics.warning_counts()
    for k in range(N_STEPS):
        step = k + 1
        if space == ARM:
            d.ctrl[:] = controls[k]
        if brought is not None:  # her hand on her path; the weld brings the toy along
            d.mocap_pos[physics.caregiver_hand_mocap, :2] = brought.path[k]
        physics.advance(CONTROL_SUBSTEPS)
        if space == ARM:
            events += backend._take_by_contact(physics, step)  # type: ignore[attr-defined]
        physics.write_tracked_positions(positions[step])
        if trace is not None:
            trace.record(step, d)
    if (physics.warning_counts() > warnings).any() or not np.isfinite(positions).all():
        positions[1:] = positions[0]
        if trace is not None:
            trace.qpos[1:], trace.mocap_pos[1:] = trace.qpos[0], trace.mocap_pos[0]
        before = backend._before  # type: ignore[attr-defined]
        return MovementOutcome(positions, sound, [], NOTHING_HELD, diverged_from=before)
    return MovementOutcome(positions, sound, events, backend.holds)


def _positions_from(start: np.ndarray) -> np.ndarray:
    positions = np.empty((N_STEPS + 1, len(TRACKED_OBJECTS), 2))
    positions[0] = start
    return positions
