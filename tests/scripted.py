"""Arm commands found by optimisation, for scripted scenes: tests, demos and videos.

A command is planned on the analytic kinematics: the hand path through the waypoints (linear
between them, from the rest position) is turned into joint angles by inverse kinematics, and
the 21 DMP parameters are fitted to those angles by bounded least squares (the DMP is linear in
its parameters). The physics then decides what really happens.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.optimize import lsq_linear

from models.layout import ARM_BASIS_FUNCTIONS, N_JOINTS, N_STEPS
from sim.config import DEFAULT_WORLD, WorldConfig
from sim.dmp import arm_trajectory, response_matrix
from sim.kinematics import hand_positions

WAYPOINT_WEIGHT = 10.0


@dataclass(frozen=True)
class Waypoint:
    """The hand at `position` (m) after control step `step` (1-based), with the last segment
    pointing along `angle` (rad; by default, away from the arm's base)."""

    step: int
    position: tuple[float, float]
    angle: float | None = None


def _inverse_kinematics(
    position: np.ndarray, angle: float, elbow: float, config: WorldConfig
) -> np.ndarray:
    """(3,) joint angles relative to rest putting the hand at `position` with orientation
    `angle`; elbow = +1 or -1 picks the elbow's side. Unreachable wrists are pulled in."""
    l1, l2, l3 = config.segment_lengths
    wrist = position - l3 * np.array([np.cos(angle), np.sin(angle)])
    r = np.clip(np.linalg.norm(wrist), abs(l1 - l2) + 1e-6, l1 + l2 - 1e-6)
    theta2 = elbow * np.arccos((r**2 - l1**2 - l2**2) / (2 * l1 * l2))
    theta1 = np.arctan2(wrist[1], wrist[0]) - np.arctan2(
        l2 * np.sin(theta2), l1 + l2 * np.cos(theta2)
    )
    q = np.array([theta1 - config.arm_rest_offset, theta2, angle - theta1 - theta2])
    return np.angle(np.exp(1j * q))  # wrapped to [-pi, pi]


def _hand_path(waypoints: list[Waypoint], config: WorldConfig) -> tuple[np.ndarray, np.ndarray]:
    """(n_steps, 2) positions and (n_steps,) angles, linear between waypoints from rest."""
    steps = [0] + [w.step for w in waypoints]
    rest = hand_positions(np.zeros(3), config)
    points = np.vstack([rest] + [w.position for w in waypoints])
    headings = [config.arm_rest_offset] + [
        w.angle if w.angle is not None else float(np.arctan2(w.position[1], w.position[0]))
        for w in waypoints
    ]
    angles = np.unwrap(headings)
    t = np.arange(1, N_STEPS + 1)
    path = np.column_stack([np.interp(t, steps, points[:, i]) for i in range(2)])
    return path, np.interp(t, steps, angles)


def arm_command_through(
    waypoints: list[Waypoint], config: WorldConfig = DEFAULT_WORLD
) -> tuple[np.ndarray, float]:
    """The (21,) command in [-1, 1] whose hand follows the waypoints, and its error: the largest
    distance (m) between the hand and a waypoint, on the analytic kinematics."""
    path, angles = _hand_path(waypoints, config)
    response = response_matrix(ARM_BASIS_FUNCTIONS, N_STEPS, config.dmp)  # start, end, weights
    # Per joint, the trajectory (before clipping, in units of pi) is end * R[1] + w @ R[2:].
    design = np.vstack([response[1], config.dmp_weight_scale * response[2:]]).T
    # The waypoints matter more than the straight lines drawn between them.
    weight = np.ones(N_STEPS)
    weight[[w.step - 1 for w in waypoints]] = WAYPOINT_WEIGHT
    best: tuple[np.ndarray, float] | None = None
    for elbow in (1.0, -1.0):
        q = np.array(
            [_inverse_kinematics(p, a, elbow, config) for p, a in zip(path, angles, strict=True)]
        )
        q = np.unwrap(q, axis=0) / np.pi
        m = np.empty((N_JOINTS, ARM_BASIS_FUNCTIONS + 1))
        for j in range(3):
            fit = lsq_linear(design * weight[:, None], q[:, j] * weight, bounds=(-1.0, 1.0))
            m[j, -1], m[j, :-1] = fit.x[0], fit.x[1:]
        command = m.ravel()
        hand = hand_positions(arm_trajectory(command, config), config)
        error = max(
            float(np.linalg.norm(hand[w.step - 1] - np.asarray(w.position))) for w in waypoints
        )
        if best is None or error < best[1]:
            best = (command, error)
    assert best is not None  # both elbows were tried
    return best
