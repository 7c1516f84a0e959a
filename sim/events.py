"""What happened during one movement, as a list of events the learner's logs and the videos use."""

from __future__ import annotations

from dataclasses import dataclass

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
)


@dataclass(frozen=True)
class Event:
    """One thing that happened at control step `step` (1-based; 0 = before the movement)."""

    kind: str
    step: int
    obj: str | None = None
    by: str | None = None
    word: str | None = None
