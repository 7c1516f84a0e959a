"""The study's kinematic rules over a whole arm movement, compiled (numba): the closed form of
sim/grasping/kinematic.py, whose `arm_movement` computes the segment angles' cosines and sines
with NumPy and hands them to this kernel.

Why compiled: the rules are a few dozen operations on arrays of 50 steps and 4 objects, and in
NumPy each operation cost a Python call (40 us a movement, a sixth of a kinematic iteration).
Every number here is computed as NumPy computed it: the same operations in the same order, each
rounded on its own (no fused multiply-add), and distances by the C library's `hypot`, which is
NumPy's. tests/sim/test_kinematic_paths.py holds the closed form to the step-by-step rules
and tests/sim/test_same_numbers_faster.py the distances to NumPy's.
"""

from __future__ import annotations

import math

import numpy as np

from sim.compiled import compiled

NONE = -1  # no object, no step
# The kernel's answers, (5,) int64: where the hand's first grasp happens and what it takes...
GRASP_STEP, GRASPED = 0, 1  # 0-based step (n_steps if none); 0 the stick, 1-3 a toy (NONE)
ON_LYING_STICK = 2  # the toy the lying stick's tip caught at the first step (study's rule)
CAUGHT_STEP, CAUGHT_TOY = 3, 4  # the held stick's catch: 0-based step and toy (NONE)


@compiled
def _first_near(
    xy: np.ndarray, objects: np.ndarray, allowed: np.ndarray, distance: float, start: int
) -> tuple[int, int]:  # pragma: no cover - compiled; tested through the rules
    """(first step >= start at which a point of xy (n, 2) lies within `distance` of an allowed
    object of objects (m, 2), the first such object), or (n, NONE). The offset is object minus
    point, as NumPy's broadcast computed it."""
    for s in range(start, xy.shape[0]):
        for o in range(objects.shape[0]):
            if allowed[o]:
                dx = objects[o, 0] - xy[s, 0]
                dy = objects[o, 1] - xy[s, 1]
                if math.hypot(dx, dy) < distance:
                    return s, o
    return xy.shape[0], NONE


@compiled
def arm_movement_rules(
    cos: np.ndarray,
    sin: np.ndarray,
    lengths: np.ndarray,
    stick_pose: np.ndarray,
    toys: np.ndarray,
    lying_tip: np.ndarray,
    study_catch: bool,
    distances: np.ndarray,
    positions: np.ndarray,
    answers: np.ndarray,
) -> None:  # pragma: no cover - compiled; tested against the step-by-step rules
    """Fill positions (n, 5, 2) (hand, stick handle, toy1-3 after each step) and answers (5,)
    (the indices above) for an arm whose segments have absolute angles with cosines and sines
    cos, sin (3, n) and lengths (3,); the stick lies at stick_pose (3,) with its tip at
    lying_tip (2,), toys (3, 2); distances: (grasp, catch, stick length).
    study_catch: the lying stick's tip catches a toy (catch_rule "study")."""
    n = cos.shape[1]
    grasp, catch, stick_length = distances[0], distances[1], distances[2]
    objects = np.empty((4, 2))  # the stick's handle, then the toys
    objects[0] = stick_pose[:2]
    objects[1:] = toys
    l0, l1, l2 = lengths[0], lengths[1], lengths[2]
    for s in range(n):
        # (l0 c0 + l1 c1) + l2 c2: NumPy's sum over the segments, in its order.
        positions[s, 0, 0] = (l0 * cos[0, s] + l1 * cos[1, s]) + l2 * cos[2, s]
        positions[s, 0, 1] = (l0 * sin[0, s] + l1 * sin[1, s]) + l2 * sin[2, s]
        positions[s, 1:] = objects
    hand = positions[:, 0]
    allowed = np.ones(4, dtype=np.bool_)
    k, first = _first_near(hand, objects, allowed, grasp, 0)
    on_stick = NONE
    if study_catch and not (k == 0 and first == 0):
        # The lying stick's tip catches a toy at the first step or never (nothing moves before
        # the hand takes something), after the hand's pick of that step, if any.
        if k == 0:
            allowed[first] = False
        tip = np.empty((1, 2))
        tip[0] = lying_tip
        caught, toy = _first_near(tip, toys, allowed[1:], catch, 0)
        if toy != NONE:
            on_stick = toy
            positions[:, 2 + toy] = lying_tip
            allowed[1 + toy] = False
            if k > 0:  # the hand's first grasp comes later: the caught toy is not free
                k, first = _first_near(hand, objects, allowed, grasp, 0)
    answers[GRASP_STEP], answers[GRASPED], answers[ON_LYING_STICK] = k, first, on_stick
    answers[CAUGHT_STEP], answers[CAUGHT_TOY] = NONE, NONE
    if k == n or first > 0:
        if first > 0:  # a toy in the hand from step k on
            positions[k:, 1 + first] = hand[k:]
        return
    positions[k:, 1] = hand[k:]  # the stick in the hand, pointing along the last segment
    tip = np.empty((n, 2))
    for s in range(k, n):
        tip[s, 0] = hand[s, 0] + stick_length * cos[2, s]
        tip[s, 1] = hand[s, 1] + stick_length * sin[2, s]
    if on_stick != NONE:
        positions[k:, 2 + on_stick] = tip[k:]
        return
    c, toy = _first_near(tip, toys, allowed[1:], catch, k)
    if toy != NONE:
        positions[c:, 2 + toy] = tip[c:]
        answers[CAUGHT_STEP], answers[CAUGHT_TOY] = c, toy
