"""The study's kinematic rules over a whole movement at once (docs/protocol.md §5, §6).

In the kinematic backend the arm follows its joint targets exactly and objects move only when
held, or carried by the caregiver, so a movement is closed-form geometry: the hand's path is the
forward kinematics of the 50 targets in one array operation, the grasp and catch rules fire at
the first step at which a distance drops below its threshold, and held objects follow the hand
(or the held stick's tip) from that step on. This is the same rule, step for step, as
`sim.grasp.KinematicGrasp` driven through the dm_control task, which the room still uses when
step observers watch (videos); tests/test_kinematic_paths.py compares the two on thousands of
commands, sample by sample and event by event.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from models.layout import N_STEPS, TOYS
from sim import events as ev
from sim.config import WorldConfig
from sim.kinematics import hand_positions


@dataclass
class ArmMovement:
    """What an arm movement does to the room.

    positions: (N_STEPS, 5, 2) hand, stick handle, toy1-3 after each control step (m).
    stick_pose: (3,) handle x, y (m) and yaw (rad) after the movement.
    events: grasps and catches, in step order. hand_holds: what the hand holds at the end.
    """

    positions: np.ndarray
    stick_pose: np.ndarray
    events: list[ev.Event]
    hand_holds: str | None


def arm_movement(
    config: WorldConfig, joint_targets: np.ndarray, stick_pose: np.ndarray, toys: np.ndarray
) -> ArmMovement:
    """Apply the rules to joint targets (3, N_STEPS) rad from a room whose stick is at
    `stick_pose` (3,) and toys at `toys` (3, 2), the arm starting at rest."""
    hand = hand_positions(joint_targets, config)  # (N_STEPS, 2)
    yaw = np.cumsum(joint_targets, axis=0)[-1] + config.arm_rest_offset  # (N_STEPS,)
    positions = np.empty((N_STEPS, 2 + len(TOYS), 2))
    positions[:, 0] = hand
    positions[:, 1] = stick_pose[:2]
    positions[:, 2:] = toys
    events: list[ev.Event] = []
    free = np.ones(len(TOYS), dtype=bool)
    on_stick = None  # the toy on the stick's tip
    # Until the hand takes something nothing moves, so every distance is to a still object.
    near = np.empty((N_STEPS, 1 + len(TOYS)), dtype=bool)
    near[:, 0] = np.hypot(*(stick_pose[:2] - hand).T) < config.grasp_distance
    for i in range(len(TOYS)):
        near[:, 1 + i] = np.hypot(*(toys[i] - hand).T) < config.grasp_distance
    grab_steps = np.flatnonzero(near.any(axis=1))
    k = int(grab_steps[0]) if grab_steps.size else N_STEPS  # 0-based: control step k + 1
    first = int(np.argmax(near[k])) if k < N_STEPS else -1  # the stick first, then the toys
    if config.catch_rule == "study" and not (k == 0 and first == 0):
        # The lying stick's tip catches a toy at the first step or never (nothing moves before
        # the hand takes something), after the hand's pick of that step, if it made one.
        if k == 0:
            free[first - 1] = False
        lying_tip = stick_pose[:2] + config.stick_length * np.array(
            [np.cos(stick_pose[2]), np.sin(stick_pose[2])]
        )
        caught = (np.hypot(*(toys - lying_tip).T) < config.catch_distance) & free
        if caught.any():
            on_stick = int(np.argmax(caught))
            positions[:, 2 + on_stick] = lying_tip
            free[on_stick] = False
            events.append(ev.Event(ev.TOY_CAUGHT, 1, obj=TOYS[on_stick], by="stick"))
            if k > 0:  # the hand's first grasp comes later: the caught toy is no longer free
                near[:, 1:] &= free
                grab_steps = np.flatnonzero(near.any(axis=1))
                k = int(grab_steps[0]) if grab_steps.size else N_STEPS
                first = int(np.argmax(near[k])) if k < N_STEPS else -1
    final_stick = np.array(stick_pose, dtype=float)
    if k == N_STEPS:
        return ArmMovement(positions, final_stick, events, None)
    if first > 0:
        toy = first - 1
        positions[k:, 2 + toy] = hand[k:]
        events.insert(0, ev.Event(ev.TOY_GRASPED, k + 1, obj=TOYS[toy], by="hand"))
        return ArmMovement(positions, final_stick, _in_step_order(events), TOYS[toy])
    events.append(ev.Event(ev.STICK_GRASPED, k + 1, obj="stick", by="hand"))
    positions[k:, 1] = hand[k:]
    final_stick = np.array([*hand[-1], yaw[-1]])
    # The held stick points along the hand: its tip carries a toy caught before, or catches
    # the first toy within reach.
    tip = hand[k:] + config.stick_length * np.stack([np.cos(yaw[k:]), np.sin(yaw[k:])], axis=1)
    if on_stick is not None:
        positions[k:, 2 + on_stick] = tip
        return ArmMovement(positions, final_stick, _in_step_order(events), "stick")
    caught = np.empty((N_STEPS - k, len(TOYS)), dtype=bool)
    for i in range(len(TOYS)):
        caught[:, i] = (np.hypot(*(toys[i] - tip).T) < config.catch_distance) & free[i]
    catch_steps = np.flatnonzero(caught.any(axis=1))
    if catch_steps.size:
        c = int(catch_steps[0])
        toy = int(np.argmax(caught[c]))
        positions[k + c :, 2 + toy] = tip[c:]
        events.append(ev.Event(ev.TOY_CAUGHT, k + c + 1, obj=TOYS[toy], by="stick"))
    return ArmMovement(positions, final_stick, _in_step_order(events), "stick")


def _in_step_order(events: list[ev.Event]) -> list[ev.Event]:
    """Events by step; within a step, the hand's grasp before the stick's catch."""
    order = {ev.STICK_GRASPED: 0, ev.TOY_GRASPED: 0, ev.TOY_CAUGHT: 1}
    return sorted(events, key=lambda e: (e.step, order[e.kind]))


def voice_grasp(config: WorldConfig, hand: np.ndarray, stick_pose: np.ndarray) -> bool:
    """With the study's catch rule, whether the resting hand at `hand` (2,) takes the stick
    during a vocal movement (its handle within the grasp distance)."""
    if config.catch_rule != "study":
        return False
    return bool(np.hypot(*(stick_pose[:2] - hand)) < config.grasp_distance)


def brought_path(rate: float, start: np.ndarray, target: np.ndarray) -> np.ndarray:
    """(N_STEPS, 2) positions of a toy the caregiver brings from `start` toward `target`,
    `rate` of the remaining way per control step (the step-by-step arithmetic, repeated)."""
    path = np.empty((N_STEPS, 2))
    position = np.array(start, dtype=float)
    for k in range(N_STEPS):
        position += rate * (target - position)
        path[k] = position
    return path
