"""One movement of the room (50 control steps of an arm or a vocal trajectory): what it did
(`MovementOutcome`) and, when asked, where everything was after each of its steps
(`MovementTrace`).

Each grasp backend computes a movement one way (`GraspBackend.simulate`: the kinematic rules
in closed form, the physical steps in compiled code) and returns a `MovementOutcome`; everything
around it that does not depend on the backend (the caregiver hearing the agent before it;
after it, which objects moved and by what, her word, her putting a toy down) is done once, by
`Playroom` (sim/playroom.py). Videos, the viewer and Gymnasium's frames draw from the trace
after the movement (`posed`): nothing watches inside the stepping. The step-by-step Python
forms of the rules live in tests/sim/stepped_oracle.py, the oracle the backends are held to.
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass
from typing import TYPE_CHECKING, NamedTuple, TypeVar

import numpy as np

from models.layout import N_STEPS
from sim import events as ev
from sim.mujoco_import import mujoco

if TYPE_CHECKING:
    from sim.dm_control_import import dm_mujoco

# The room's physics (sim/physics.py, which itself reads this module's trace).
PhysicsT = TypeVar("PhysicsT", bound="dm_mujoco.Physics")


ARM = "arm"
VOICE = "voice"


class Holds(NamedTuple):
    """What the hand holds ("stick", "toy1", ... or None) and which toy the stick's tip holds
    (0-based, or None)."""

    hand: str | None
    stick: int | None


NOTHING_HELD = Holds(None, None)


class Brought(NamedTuple):
    """The toy the caregiver brings during a movement (0-based) and where it is to be after
    each control step, (N_STEPS, 2): her path (sim/caregiver.py)."""

    toy: int
    path: np.ndarray


class Movement(NamedTuple):
    """A movement as the room asks a backend for it.

    space: "arm" or "voice". controls: (N_STEPS, 3) joint targets (rad, relative to rest) of an
    arm movement (a vocal one's are not read). start: (5, 2) the tracked positions before it.
    sound: (N_STEPS, 2) the sound sensor's values, the outcome's. brought: the toy the caregiver
    brings during it and her path, or None.
    """

    space: str
    controls: np.ndarray
    start: np.ndarray
    sound: np.ndarray
    brought: Brought | None


@dataclass
class MovementTrace:
    """Where everything was during a movement: what a frame of it needs.

    qpos: (N_STEPS + 1, nq) MuJoCo's joint positions (the arm's joints, the objects' x, y and
    yaw), row 0 before the movement, row k after control step k. mocap_pos: (N_STEPS + 1,
    nmocap, 3) the mocap bodies (the caregiver and her hand), rows as qpos's.
    """

    qpos: np.ndarray
    mocap_pos: np.ndarray

    @classmethod
    def starting_at(cls, data: mujoco.MjData) -> MovementTrace:
        """A trace whose every row is the room as `data` holds it now (the backends overwrite
        the rows of the steps)."""
        qpos = np.empty((N_STEPS + 1, *data.qpos.shape))
        qpos[:] = data.qpos
        mocap = np.empty((N_STEPS + 1, *data.mocap_pos.shape))
        mocap[:] = data.mocap_pos
        return cls(qpos, mocap)

    def record(self, step: int, data: mujoco.MjData) -> None:
        """Row `step` from the room as `data` holds it now."""
        self.qpos[step] = data.qpos
        self.mocap_pos[step] = data.mocap_pos

    def replayed(self, physics: PhysicsT) -> Iterator[tuple[int, PhysicsT]]:
        """(step, a copy of `physics` posed after that control step) for steps 1..N_STEPS: the
        copy shares the model and has its own data, so the room itself is never computed on.
        Its measurements (hand_position, contacts, ...) are the room's at that step, but for
        what the backend's holds change in the model (welds, a held object's collisions), which
        are gone once the movement ended."""
        copy = physics.copy(share_model=True)
        data = copy.data.ptr
        for step in range(1, len(self.qpos)):
            posed(copy.model.ptr, data, self, step)
            yield step, copy


def posed(
    model: mujoco.MjModel, data: mujoco.MjData, trace: MovementTrace, step: int
) -> mujoco.MjData:
    """`data` (a scratch MjData of `model`, never the room's own) put where the room was after
    control step `step` of `trace` (`posed_as`). The mocap bodies' orientations are left as
    `data` holds them (no movement turns one)."""
    return posed_as(model, data, trace.qpos[step], trace.mocap_pos[step])


def posed_as(
    model: mujoco.MjModel,
    data: mujoco.MjData,
    qpos: np.ndarray,
    mocap_pos: np.ndarray,
    mocap_quat: np.ndarray | None = None,
) -> mujoco.MjData:
    """`data` (a scratch MjData of `model`) put still at these joint and mocap positions (and
    orientations, if given), every derived quantity computed (mj_forward): what a frame, a
    viewer or a contact list reads."""
    data.qpos[:] = qpos
    data.qvel[:] = 0.0
    data.mocap_pos[:] = mocap_pos
    if mocap_quat is not None:
        data.mocap_quat[:] = mocap_quat
    mujoco.mj_forward(model, data)
    return data


@dataclass
class MovementOutcome:
    """What one movement did, before the room finishes it.

    positions: (N_STEPS + 1, 5, 2) hand, stick handle, toy1-3; row 0 before the movement, row k
    after control step k (m). sound: (N_STEPS, 2) the sound sensor at each step. events: what
    the backend saw happen (grasps, catches), in step order. holds: what is held at the end.
    still: nothing can have moved (no movement events to look for). diverged_from: MuJoCo's
    state before a movement whose physics diverged, to be put back; None otherwise.
    """

    positions: np.ndarray
    sound: np.ndarray
    events: list[ev.Event]
    holds: Holds
    still: bool = False
    diverged_from: np.ndarray | None = None
