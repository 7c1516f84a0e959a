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
    final_stick = np.array(stick_pose, dtype=float)
    events: list[ev.Event] = []
    # Until the hand takes something nothing moves, so every distance is to a still object.
    near = np.empty((N_STEPS, 1 + len(TOYS)), dtype=bool)
    near[:, 0] = np.hypot(*(stick_pose[:2] - hand).T) < config.grasp_distance
    for i in range(len(TOYS)):
        near[:, 1 + i] = np.hypot(*(toys[i] - hand).T) < config.grasp_distance
    grab_steps = np.flatnonzero(near.any(axis=1))
    if grab_steps.size == 0:
        return ArmMovement(positions, final_stick, events, None)
    k = int(grab_steps[0])  # 0-based: control step k + 1
    first = int(np.argmax(near[k]))  # the stick first, then the toys in order
    if first > 0:
        toy = first - 1
        positions[k:, 2 + toy] = hand[k:]
        events.append(ev.Event(ev.TOY_GRASPED, k + 1, obj=TOYS[toy], by="hand"))
        return ArmMovement(positions, final_stick, events, TOYS[toy])
    events.append(ev.Event(ev.STICK_GRASPED, k + 1, obj="stick", by="hand"))
    positions[k:, 1] = hand[k:]
    final_stick = np.array([*hand[-1], yaw[-1]])
    # The held stick points along the hand: its tip catches the first toy within reach.
    tip = hand[k:] + config.stick_length * np.stack([np.cos(yaw[k:]), np.sin(yaw[k:])], axis=1)
    caught = np.empty((N_STEPS - k, len(TOYS)), dtype=bool)
    for i in range(len(TOYS)):
        caught[:, i] = np.hypot(*(toys[i] - tip).T) < config.catch_distance
    catch_steps = np.flatnonzero(caught.any(axis=1))
    if catch_steps.size:
        c = int(catch_steps[0])
        toy = int(np.argmax(caught[c]))
        positions[k + c :, 2 + toy] = tip[c:]
        events.append(ev.Event(ev.TOY_CAUGHT, k + c + 1, obj=TOYS[toy], by="stick"))
    return ArmMovement(positions, final_stick, events, "stick")


def brought_path(rate: float, start: np.ndarray, target: np.ndarray) -> np.ndarray:
    """(N_STEPS, 2) positions of a toy the caregiver brings from `start` toward `target`,
    `rate` of the remaining way per control step (the step-by-step arithmetic, repeated)."""
    path = np.empty((N_STEPS, 2))
    position = np.array(start, dtype=float)
    for k in range(N_STEPS):
        position += rate * (target - position)
        path[k] = position
    return path
