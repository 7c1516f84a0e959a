"""Plane geometry without the physics: the arm's analytic forward kinematics (docs/protocol.md §1),
used to check the MJCF model, to run the kinematic rules and to plan scripted commands; and the
distance from a point to a segment (the stick)."""

from __future__ import annotations

import numpy as np

from sim.config import DEFAULT_WORLD, WorldConfig


def hand_positions(joint_angles: np.ndarray, config: WorldConfig = DEFAULT_WORLD) -> np.ndarray:
    """(3, ...) joint angles relative to rest (rad) -> (..., 2) hand positions (m).

    The hand is the sum of the segment vectors at the cumulative angles, turned by the rest
    offset so that zero angles point the arm along +y.
    """
    q = np.asarray(joint_angles, dtype=float)
    absolute = np.cumsum(q, axis=0) + config.arm_rest_offset
    lengths = np.asarray(config.segment_lengths).reshape((3,) + (1,) * (q.ndim - 1))
    x = (lengths * np.cos(absolute)).sum(axis=0)
    y = (lengths * np.sin(absolute)).sum(axis=0)
    return np.stack([x, y], axis=-1)


def segment_distance(point: np.ndarray, a: np.ndarray, b: np.ndarray) -> float:
    """Distance (m) from `point` to the segment [a, b]."""
    ab = b - a
    t = np.clip(np.dot(point - a, ab) / np.dot(ab, ab), 0.0, 1.0)
    return float(np.linalg.norm(point - (a + t * ab)))
