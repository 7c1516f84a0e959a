"""The contact ladder's rung 2 (WorldConfig.arm_dynamics "servo"): the kinematic rules
acting on the arm the physical model's servos move, touching nothing. The arm lags its targets
as the physical backend's does, to the bit in a room whose objects it never touches; grasps and
catches stay the rules' distances, and nothing moves an object but a grasp or a catch."""

from __future__ import annotations

import numpy as np
import pytest

from models.layout import ARM_DIM, TRACKED_OBJECTS
from sim import Playroom
from sim import events as ev
from sim.arm_servo import ArmServo
from sim.config import inert_settings, world_preset
from sim.dmp import arm_trajectory

SERVO = world_preset("study", arm_dynamics="servo")
# Where nothing is within the hand's or the stick's reach: the room is empty for the arm.
FAR_STICK = (1.2, -1.2, 0.0)
FAR_TOYS = np.array([[-1.2, -1.2], [1.2, 1.2], [-1.2, 1.2]])


def _arm_angles_and_hands(grasp: str, commands: list[np.ndarray]) -> tuple[list, list]:
    """Per command: the (50, 3) joint angles after each control step (read from the
    movement's trace) and the feedback's (50, 2) hand path, in an empty room of `grasp`."""
    room = Playroom(grasp, seed=0, config=SERVO if grasp == "kinematic" else world_preset("study"))
    room.tracing = True
    angles, hands = [], []
    for m in commands:
        room.arrange(stick=FAR_STICK, toys=FAR_TOYS)  # placements between iterations undone
        feedback = room.act_arm(m)
        assert not {ev.STICK_GRASPED, ev.TOY_GRASPED, ev.TOY_CAUGHT} & set(feedback.kinds())
        assert room.last_trace is not None
        angles.append(room.last_trace.qpos[1:, room.physics.arm_qpos])
        hands.append(feedback.positions[:, 0].copy())
    return angles, hands


def test_the_servo_arm_is_the_physical_backends_arm_in_an_empty_room():
    rng = np.random.default_rng(4)
    commands = [rng.uniform(-1, 1, ARM_DIM) for _ in range(8)]
    servo_angles, servo_hands = _arm_angles_and_hands("kinematic", commands)
    physical_angles, physical_hands = _arm_angles_and_hands("physical", commands)
    for mine, theirs in zip(servo_angles, physical_angles, strict=True):
        np.testing.assert_allclose(mine, theirs, rtol=0, atol=1e-12)
    # The kinematic rules' analytic hand and MuJoCo's hand site agree to rounding.
    np.testing.assert_allclose(servo_hands, physical_hands, rtol=0, atol=1e-12)
    # And the arm lags its targets: the angles are not the targets, nor the hand the set one's.
    set_room = Playroom("kinematic", seed=0, config=world_preset("study"))
    lags = []
    for m, angles, hand in zip(commands, servo_angles, servo_hands, strict=True):
        lags.append(np.abs(angles - arm_trajectory(m, SERVO).T).max())
        set_room.arrange(stick=FAR_STICK, toys=FAR_TOYS)
        set_hand = set_room.act_arm(m).positions[:, 0]
        lags[-1] = min(lags[-1], np.hypot(*(hand - set_hand).T).max())
    assert min(lags) > 1e-3  # rad and m: over a millimetre for every command


def test_the_servo_path_is_the_same_steps_from_rest():
    targets = arm_trajectory(np.random.default_rng(0).uniform(-1, 1, ARM_DIM), SERVO)
    servo = ArmServo()
    whole = servo.path(targets)
    servo.step(np.ones(3))  # a movement left half done: `path` starts again from rest
    np.testing.assert_array_equal(servo.path(targets), whole)
    servo.reset()
    stepped = np.stack([servo.step(targets[:, k]) for k in range(targets.shape[1])], axis=1)
    np.testing.assert_array_equal(stepped, whole)


def test_the_servo_arm_grasps_by_distance_and_pushes_nothing():
    room = Playroom("kinematic", seed=3, config=SERVO)
    rng = np.random.default_rng(3)
    grasps = catches = 0
    for _ in range(300):
        start = room.physics.tracked_positions()
        feedback = room.act_arm(rng.uniform(-1, 1, ARM_DIM))
        hand = feedback.positions[:, 0]
        for e in feedback.events:
            # Only a grasp or a catch moves an object (no caregiver brings during arm moves).
            if e.kind in (ev.STICK_MOVED, ev.TOY_MOVED):
                assert e.by in ("hand", "stick"), e
            if e.kind in (ev.STICK_GRASPED, ev.TOY_GRASPED):
                # The hand took it at the first step it came within the grasp distance of
                # where the object lay: nothing moves an object before it is taken, and an
                # empty hand takes the first free object it comes near.
                lay = start[TRACKED_OBJECTS.index(e.obj)]
                near = np.hypot(*(hand - lay).T) < SERVO.grasp_distance
                assert near.any() and int(np.argmax(near)) + 1 == e.step, e
                grasps += 1
        catches += ev.TOY_CAUGHT in feedback.kinds()
    assert grasps > 50 and catches > 5


def test_the_switch_is_the_kinematic_backends_and_checked():
    with pytest.raises(ValueError, match="arm_dynamics"):
        world_preset("study", arm_dynamics="servos")
    assert inert_settings("physical", {"arm_dynamics": "servo"}) == ["arm_dynamics"]
    assert inert_settings("kinematic", {"arm_dynamics": "servo"}) == []
