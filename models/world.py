"""What a world is to the learner: a context, and feedback for a command in a motor space.

`sim.Playroom` (the MuJoCo playroom) and `SyntheticWorld` (tests/synthetic.py, a cheap
stand-in for the learner's own tests) both implement `World`; the trial loop, evaluation, replay and
video drive either through `act`, and nothing else dispatches on the motor space.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any, Protocol


class _ComputedOnRead:
    """A dataclass field that may be given a function of no arguments instead of its value:
    the function runs at the first read, and its value is kept. For a value that costs time
    and that most callers never read."""

    def __set_name__(self, owner: type, name: str) -> None:
        self._slot = f"_{name}"

    def __get__(self, obj: Any, owner: type | None = None) -> Any:
        if obj is None:  # the dataclass asks for the field's default
            return None
        value = obj.__dict__[self._slot]
        if isinstance(value, Callable):  # type: ignore[arg-type]
            value = value()
            obj.__dict__[self._slot] = value
        return value

    def __set__(self, obj: Any, value: Any) -> None:
        obj.__dict__[self._slot] = value


@dataclass
class Feedback:
    """What the agent perceives of one movement.

    s: (60,) the sensory blocks of models/layout.py: hand, stick handle, toy1, toy2, toy3 (each
    5 x then 5 y at the sample steps) and sound (5 normalised log2 F1 then 5 log2 F2).
    events: what happened, in step order (the world's own event objects).
    positions: (50, 5, 2) the tracked objects after every control step, if the world has them.
    sound: (50, 2) the sound sensor after every control step, if the world has it (a world
    may pass a function that computes it: it then runs when `sound` is first read).
    """

    motor_space: str
    s: Any
    events: list = field(default_factory=list)
    positions: Any = None
    sound: Any = _ComputedOnRead()

    def kinds(self) -> list[str]:
        return [e.kind for e in self.events]


class World(Protocol):
    """A world the agent plays in (models/layout.py gives every size)."""

    def context(self) -> Any:
        """(10,) the context slots' positions before the next movement."""

    def act(self, motor_space: str, m: Any) -> Feedback:
        """Execute command m of `motor_space` ('arm' (21,) or 'voice' (28,)) in [-1, 1]."""
