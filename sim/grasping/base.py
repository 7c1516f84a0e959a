"""What every grasp backend offers the room: the interface, and what the backends share.

A backend decides how the world moves: what the arm does with its joint targets, what the hand
and the stick's tip take, and when the stick has left the hand's reach. It is made of parts,
which it declares and the playroom builds and hands it (sim/playroom.py, `compose_backend`):
the physics it moves (`physics_class`), how the caregiver carries a toy she brings
(`carrying_class`, sim/grasping/carrying.py) and, where the grasp rule is a part of its own, the
rule (`rule_class`: the physical backend's contact rule, sim/grasping/contact_rule.py; the
kinematic rules are computed with their geometry in one compiled kernel). It
computes a whole movement one way (`simulate`), returning what it did and, when asked, its
trace (sim/movement.py); `release(physics)` ends a movement: everything held is dropped where
it is and the arm goes back to rest. The step-by-step Python forms of the backends' rules, the
oracle they are held to bit for bit, are in tests/stepped_oracle.py.
"""

from __future__ import annotations

import abc
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np

from sim import events as ev
from sim.config import WorldConfig
from sim.grasping.carrying import Carrying, PlacedCarrying
from sim.model_edits import ModelEdits
from sim.movement import NOTHING_HELD, Holds, Movement, MovementOutcome, MovementTrace
from sim.physics import PlayroomPhysics

__all__ = ["NOTHING_HELD", "ArmMovement", "GraspBackend", "Holds", "arm_to_rest"]


class GraspBackend(abc.ABC):
    """What the hand holds and what the stick's tip holds, and how that changes.

    Class attributes: `name`, as the registry, the command line and config.json name it;
    `physics_class`, the physics the room loads for it; `solid`, whether objects are solid
    bodies (placements keep clear of each other: sim/experimenter.py); `closed_form`, whether
    its movements are geometry computed whole rather than dynamics stepped (recorded with the
    trial: experiments/backend_record.py).
    """

    name: str
    solid: bool
    closed_form: bool
    # Its parts, declared here and built by the playroom (the module's docstring): each is
    # built with the world's config and the model's edits, the rule also with the backend's
    # name (under which it edits the model).
    physics_class: type[PlayroomPhysics] = PlayroomPhysics
    carrying_class: Callable[[ModelEdits], Carrying] = PlacedCarrying
    rule_class: Callable[[WorldConfig, ModelEdits, str], Any] | None = None

    @classmethod
    def carrying_for(cls, config: WorldConfig) -> Callable[[ModelEdits], Carrying]:
        """The caregiver's carrying in a world of `config`: `carrying_class`, unless a world
        setting the backend reads chooses another."""
        return cls.carrying_class

    def __init__(
        self, config: WorldConfig, edits: ModelEdits, carrying: Carrying, rule: Any = None
    ) -> None:
        self.config = config
        self.edits = edits  # run-time model changes, under the backend's name
        self.carrying = carrying  # how the caregiver carries a toy she brings in this world
        self.rule = rule  # the grasp rule, where it is a part of its own (else None)
        self.hand_holds: str | None = None  # "stick", "toy1", ... or None
        self.stick_holds: int | None = None  # index of the toy on the stick's tip

    # Movements of the agent ---------------------------------------------------------------
    def begin(self, physics: PlayroomPhysics) -> None:
        """Start of a movement, before the caregiver hears it: nothing is held."""
        self.hand_holds = None
        self.stick_holds = None

    @abc.abstractmethod
    def simulate(
        self, physics: PlayroomPhysics, movement: Movement, trace: MovementTrace | None
    ) -> MovementOutcome:
        """The whole movement `begin` began (sim/movement.py's `Movement`). Where `trace` is
        given, its rows 1..N_STEPS are the room after each control step."""

    @property
    def holds(self) -> Holds:
        """What the hand and the stick's tip hold now."""
        return Holds(self.hand_holds, self.stick_holds)

    @abc.abstractmethod
    def release(self, physics: PlayroomPhysics) -> None:
        """Drop everything where it is and put the arm back at rest."""

    def settle(self, physics: PlayroomPhysics) -> None:  # noqa: B027 (a hook, most need none)
        """Between movements, after everything is dropped: nothing to do unless the backend's
        objects can be left overlapping (the physical one, WorldConfig.settle_between_movements)."""

    @abc.abstractmethod
    def after_placements(self, physics: PlayroomPhysics) -> None:
        """Between iterations, after the experimenter and the caregiver placed things: MuJoCo's
        derived quantities brought up to what the next movement reads."""

    # The experimenter (sim/experimenter.py) -----------------------------------------------
    @abc.abstractmethod
    def stick_out_of_reach(self, physics: PlayroomPhysics) -> bool:
        """Whether this backend's grasp rule can no longer reach the stick's handle."""

    # What a trial records of its backend (backend.json: experiments/backend_record.py) ----
    @abc.abstractmethod
    def reach(self) -> float:
        """How far from the arm's base (m) the hand can take the stick's handle. Declared here,
        recorded by the trial and read by analysis and reports, which rebuild no backend rule."""

    def capabilities(self) -> dict[str, bool]:
        """What a reader of this backend's trials may need to know: `solid` (see above),
        `pushes` (an unheld object moves when something touches it: solid, unless the world
        switches pushing off or its touches to sensed only), `closed_form` (see above)."""
        held_still = not self.config.push_objects or self.config.unheld_contacts == "sensed"
        pushes = self.solid and not held_still
        return {"solid": self.solid, "pushes": pushes, "closed_form": self.closed_form}


@dataclass
class ArmMovement:
    """What an arm movement does to the room, in closed form.

    positions: (N_STEPS, 5, 2) hand, stick handle, toy1-3 after each control step (m).
    stick_pose: (3,) handle x, y (m) and yaw (rad) after the movement.
    events: grasps and catches, in step order. holds: what is held at the end.
    angles: (3, N_STEPS) the arm's joint angles after each step (rad, relative to rest);
    absolute: (3, N_STEPS) the segments' absolute angles after each step (rad): a held stick
    points along the last one.
    """

    positions: np.ndarray
    stick_pose: np.ndarray
    events: list[ev.Event]
    holds: Holds
    angles: np.ndarray
    absolute: np.ndarray


def arm_to_rest(physics: PlayroomPhysics) -> None:
    """The arm back at rest, still, with no control."""
    physics.rest_arm()
