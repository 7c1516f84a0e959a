"""One movement of the room (50 control steps of an arm or a vocal trajectory): the paths that
compute it, and the one outcome each returns.

A movement is computed
- in closed form, whole (`closed_form_movement`), where the backend's rules are geometry (the
  kinematic one, `sim.grasping.base.ClosedForm`) and no one watches the steps;
- step by step through the dm_control task (`stepped_movement`): observed, through the
  dm_control Environment, when someone watches each step (videos); unobserved, in compiled code
  where the backend has compiled stepping (the physical one; `PlayroomTask.run_steps`).

Each path returns a `MovementOutcome`. Everything around a movement that does not depend on the
path (the caregiver hearing the agent before it; after it, which objects moved and by what, her
word, her putting a toy down, the backend's release) is done once, by `Playroom` (sim/playroom.py):
a rule of the caregiver's (sim/caregiver.py) or the experimenter's is written once, whatever the
path. tests/sim/test_kinematic_paths.py holds the closed form to the stepped path, bit for bit.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from models.layout import N_STEPS, TRACKED_OBJECTS
from sim import events as ev
from sim.caregiver import Caregiver
from sim.dm_control_import import control
from sim.grasping.base import ClosedForm, Holds
from sim.physics import PlayroomPhysics
from sim.task import ARM, MovementStepper, PlayroomTask

_NOTHING_HELD = Holds(None, None)


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


def closed_form_movement(
    closed: ClosedForm,
    physics: PlayroomPhysics,
    caregiver: Caregiver,
    movement: str,
    controls: np.ndarray,
    start: np.ndarray,
    sound: np.ndarray,
) -> MovementOutcome:
    """A whole movement from the backend's closed form; MuJoCo's state is set once, at the end.

    controls: (N_STEPS, 3) joint targets of an arm movement (a vocal one's are not read).
    start: (5, 2) the tracked positions before it; sound: (N_STEPS, 2) the sensor's values.
    The caregiver has heard the agent already: a toy she brings follows her path.
    """
    positions = np.empty((N_STEPS + 1, len(TRACKED_OBJECTS), 2))
    positions[0] = start
    poses = physics.object_poses()
    events: list[ev.Event] = []
    holds = _NOTHING_HELD
    still = False
    if movement == ARM:
        # (3, N_STEPS), C-ordered as the compiled rules were compiled for (no copy: the
        # targets were made so, then transposed)
        arm = closed.arm_movement(np.ascontiguousarray(controls.T), poses[0], poses[1:, :2])
        positions[1:], events, holds = arm.positions, arm.events, arm.holds
        poses[0] = arm.stick_pose
    else:
        positions[1:] = positions[0]
        if closed.voice_grasp(positions[0, 0], poses[0]):  # the study's rule
            events.append(ev.Event(ev.STICK_GRASPED, 1, obj="stick", by="hand"))
            positions[1:, 1] = positions[0, 0]
            poses[0] = (*positions[0, 0], closed.config.arm_rest_offset)
            holds = Holds("stick", None)
        else:
            still = caregiver.bringing is None
        if caregiver.bringing is not None and caregiver.path is not None:
            positions[1:, 2 + caregiver.bringing] = caregiver.path
    poses[1:, :2] = positions[-1, 2:]
    physics.set_object_poses(poses)
    return MovementOutcome(positions, sound, events, holds, still)


def stepped_movement(
    physics: PlayroomPhysics,
    task: PlayroomTask,
    env: MovementStepper,
    observers: list[Callable[[int, dict], None]],
    actions: np.ndarray,
    start: np.ndarray,
    saved: np.ndarray,
) -> MovementOutcome:
    """The movement `task.begin_movement` began, one control step at a time: through the
    dm_control environment while `observers` watch (each called with (step, observation)),
    else `task.run_steps`. actions: (N_STEPS, 10) joint targets and articulators. start: (5, 2)
    the tracked positions before it; saved: MuJoCo's state before it, which a divergence puts
    back."""
    positions = np.empty((N_STEPS + 1, len(TRACKED_OBJECTS), 2))
    sound = np.zeros((N_STEPS, 2))
    positions[0] = start
    events: list[ev.Event] = []
    warnings = physics.warning_counts()
    try:
        if observers:
            for k in range(N_STEPS):
                obs = env.step(actions[k]).observation
                positions[k + 1] = (obs["hand"], obs["stick_handle"], *obs["toys"])
                sound[k] = obs["sound"]
                for observer in observers:
                    observer(k + 1, obs)
                events += task.step_events
        else:  # the same steps, reading only what the feedback needs
            events += task.run_steps(physics, actions, positions, sound)
        if (physics.warning_counts() > warnings).any() or not np.isfinite(positions).all():
            raise control.PhysicsError("MuJoCo warned of an invalid state")
    except control.PhysicsError:
        positions[1:] = positions[0]  # the room goes on from where it was
        return MovementOutcome(positions, sound, [], _NOTHING_HELD, diverged_from=saved)
    return MovementOutcome(positions, sound, events, task.grasp.holds)
