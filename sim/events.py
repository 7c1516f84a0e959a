"""What happened during one movement, as a list of events the learner's logs and the videos use."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from models.layout import MOVED_DISTANCE, TRACKED_OBJECTS

# Event kinds, in one place so logs, tests and overlays agree on the spelling.
STICK_GRASPED = "stick_grasped"  # the hand took the stick by its handle
TOY_GRASPED = "toy_grasped"  # the hand took a toy (obj = toy)
TOY_CAUGHT = "toy_caught"  # the stick's tip caught a toy (obj = toy)
TOY_MOVED = "toy_moved"  # a toy moved (obj = toy; by = hand | stick | caregiver | push)
STICK_MOVED = "stick_moved"  # the stick moved (by = hand | push)
WORD_RECOGNISED = "word_recognised"  # the caregiver recognised the agent's sound (word, obj)
CAREGIVER_SAID = "caregiver_said"  # the caregiver spoke a word (word, obj = toy it names)
DIVERGED = "diverged"  # the physics diverged; objects were restored to their start
FORMANT_FALLBACK = "formant_fallback"  # a frame had no formant; the fallback value was used
STICK_RETURNED = "stick_returned"  # the experimenter put a stick out of reach back (step 50)

KINDS = (
    STICK_GRASPED,
    TOY_GRASPED,
    TOY_CAUGHT,
    TOY_MOVED,
    STICK_MOVED,
    WORD_RECOGNISED,
    CAREGIVER_SAID,
    DIVERGED,
    FORMANT_FALLBACK,
    STICK_RETURNED,
)


@dataclass(frozen=True)
class Event:
    """One thing that happened at control step `step` (1-based; 0 = before the movement)."""

    kind: str
    step: int
    obj: str | None = None
    by: str | None = None
    word: str | None = None


def movement_events(
    positions: np.ndarray, step_events: list[Event], brought: str | None
) -> list[Event]:
    """Which objects moved, when first, and by what, from (51, 5, 2) positions (row 0 = start)."""
    # Compiled (it loads numba): imported at the first movement, not with the event kinds.
    from sim.moved_kernel import NOT_MOVED, first_moved_steps

    first = np.empty(positions.shape[1] - 1, dtype=np.int64)  # the hand is not an object
    if first_moved_steps(positions, MOVED_DISTANCE, first) == 0:  # most movements
        return []
    grasped = {e.obj for e in step_events if e.kind in (TOY_GRASPED, STICK_GRASPED)}
    caught = {e.obj for e in step_events if e.kind == TOY_CAUGHT}
    moved: list[Event] = []
    for row, step in enumerate(first.tolist()):
        if step == NOT_MOVED:
            continue
        name = TRACKED_OBJECTS[1 + row]
        if name == "stick":
            by = "hand" if "stick" in grasped else "push"
            moved.append(Event(STICK_MOVED, step, obj="stick", by=by))
            continue
        if name == brought:
            by = "caregiver"
        else:
            by = "hand" if name in grasped else "stick" if name in caught else "push"
        moved.append(Event(TOY_MOVED, step, obj=name, by=by))
    return moved
