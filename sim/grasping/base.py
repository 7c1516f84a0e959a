"""What every grasp backend offers the room: the interface, and what the backends share.

A backend decides how the world moves: what the arm does with its joint targets, what the hand
and the stick's tip take, how the caregiver carries a toy she brings, and when the stick has
left the hand's reach. Per control step the task calls `before_step(physics, joint_targets,
step)`, then the physics steps, then `after_step(physics, step)`; both return the events of that
step. `release(physics)` ends a movement: everything held is dropped where it is and the arm
goes back to rest. A backend whose movements are closed-form geometry also derives from
`ClosedForm`, and the room then runs unobserved movements whole (sim/playroom.py).
"""

from __future__ import annotations

import abc
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

from models.layout import TOYS
from sim import events as ev
from sim.config import WorldConfig
from sim.model_edits import ModelEdits
from sim.physics import PlayroomPhysics


class Holds(NamedTuple):
    """What the hand holds ("stick", "toy1", ... or None) and which toy the stick's tip holds
    (0-based, or None)."""

    hand: str | None
    stick: int | None


class GraspBackend(abc.ABC):
    """What the hand holds and what the stick's tip holds, and how that changes.

    Class attributes: `name`, as the registry, the command line and config.json name it;
    `physics_class`, the physics the room loads for it; `solid`, whether objects are solid
    bodies (placements keep clear of each other: sim/experimenter.py).
    """

    name: str
    physics_class: type[PlayroomPhysics] = PlayroomPhysics
    solid: bool
    # Whether `run_steps` runs a movement's control steps in compiled code (PlayroomTask).
    has_compiled_steps = False

    def __init__(self, config: WorldConfig, edits: ModelEdits) -> None:
        self.config = config
        self.edits = edits  # run-time model changes, under the backend's name
        self.hand_holds: str | None = None  # "stick", "toy1", ... or None
        self.stick_holds: int | None = None  # index of the toy on the stick's tip

    # Movements of the agent ---------------------------------------------------------------
    def begin(self, physics: PlayroomPhysics) -> None:
        """Start of a movement: nothing is held."""
        self.hand_holds = None
        self.stick_holds = None

    @abc.abstractmethod
    def before_step(
        self, physics: PlayroomPhysics, joint_targets: np.ndarray, step: int
    ) -> list[ev.Event]:
        """Drive the arm toward joint_targets (3,) rad, relative to rest."""

    @abc.abstractmethod
    def after_step(self, physics: PlayroomPhysics, step: int) -> list[ev.Event]:
        """Look at the world after the step and attach what the rules say."""

    @property
    def holds(self) -> Holds:
        """What the hand and the stick's tip hold now."""
        return Holds(self.hand_holds, self.stick_holds)

    def run_steps(
        self,
        physics: PlayroomPhysics,
        arm_targets: np.ndarray,
        brought: np.ndarray | None,
        start: int,
        positions: np.ndarray,
        grasping: bool,
    ) -> int:
        """Control steps from `start` in compiled code, as `before_step` and the caregiver's
        carrying would take them (`brought`: her path, (n, 2), or None); while `grasping` (an
        arm movement), until a contact that would take something appears: returns that step,
        whose `after_step` the caller then takes, or n. Only for a backend with
        `has_compiled_steps`."""
        raise NotImplementedError(f"the {self.name} backend has no compiled steps")

    def during_voice(self, physics: PlayroomPhysics, step: int) -> list[ev.Event]:
        """A control step of a vocal movement, the arm at rest: nothing is grasped."""
        return []

    @abc.abstractmethod
    def release(self, physics: PlayroomPhysics) -> None:
        """Drop everything where it is and put the arm back at rest."""

    def settle(self, physics: PlayroomPhysics) -> None:  # noqa: B027 (a hook, most need none)
        """Between movements, after everything is dropped: nothing to do unless the backend's
        objects can be left overlapping (the physical one, WorldConfig.settle_between_movements)."""

    # The caregiver bringing a toy (sim/caregiver.py) --------------------------------------
    @abc.abstractmethod
    def caregiver_takes(self, physics: PlayroomPhysics, toy: int) -> np.ndarray:
        """She takes toy `toy` (0-based) to bring it over the coming control steps. Returns
        (2,) where what she moves starts: her path (`Caregiver`) begins there."""

    @abc.abstractmethod
    def caregiver_carries(self, physics: PlayroomPhysics, toy: int, place: np.ndarray) -> None:
        """One control step: what she moves with toy `toy` goes to `place` (2,), the step's
        point of her path."""

    @abc.abstractmethod
    def caregiver_puts_down(self, physics: PlayroomPhysics) -> None:
        """She puts the toy down where it is."""

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
        switches pushing off), `closed_form` (movements computed whole: `ClosedForm`)."""
        pushes = self.solid and self.config.push_objects
        return {"solid": self.solid, "pushes": pushes, "closed_form": isinstance(self, ClosedForm)}

    def _free_toy_mask(self) -> np.ndarray:
        """(3,) bool: toys that neither the hand nor the stick holds."""
        free = np.ones(len(TOYS), dtype=bool)
        if self.stick_holds is not None:
            free[self.stick_holds] = False
        if self.hand_holds in TOYS:
            free[TOYS.index(self.hand_holds)] = False
        return free


@dataclass
class ArmMovement:
    """What an arm movement does to the room, in closed form.

    positions: (N_STEPS, 5, 2) hand, stick handle, toy1-3 after each control step (m).
    stick_pose: (3,) handle x, y (m) and yaw (rad) after the movement.
    events: grasps and catches, in step order. holds: what is held at the end.
    """

    positions: np.ndarray
    stick_pose: np.ndarray
    events: list[ev.Event]
    holds: Holds


class ClosedForm(GraspBackend):
    """A backend whose movements are closed-form geometry: the room computes an unobserved
    movement whole from these, with the same result, to the last bit, as stepping the backend
    through the dm_control task (tests/sim/test_kinematic_paths.py)."""

    @abc.abstractmethod
    def arm_movement(
        self, joint_targets: np.ndarray, stick_pose: np.ndarray, toys: np.ndarray
    ) -> ArmMovement:
        """The rules over joint targets (3, N_STEPS) rad from a room whose stick is at
        `stick_pose` (3,) and toys at `toys` (3, 2), the arm starting at rest."""

    @abc.abstractmethod
    def voice_grasp(self, hand: np.ndarray, stick_pose: np.ndarray) -> bool:
        """Whether the resting hand at `hand` (2,) takes the stick during a vocal movement."""


def arm_to_rest(physics: PlayroomPhysics) -> None:
    """The arm back at rest, still, with no control."""
    physics.rest_arm()
