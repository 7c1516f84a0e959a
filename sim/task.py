"""The playroom as a dm_control task: one control step is one DMP target of a movement.

The action of a step is 10 numbers: the 3 joint targets of the arm (rad, relative to rest)
and the 7 articulators of the vocal tract (in [-1, 1]). A movement uses one of the two: the
task is told which by `begin_movement`, and the other part of the action is ignored; a step
outside a movement is refused. The vocal tract is a non-physical sensor: its formants are the
`sound` observation.

`MovementStepper` is the dm_control Environment through which `Playroom` steps this task while
someone watches each step (videos). It is the room's internal stepping, not an environment to
act in: environments that act, one command a step, are in sim/envs/.
"""

from __future__ import annotations

import collections

import numpy as np
from dm_env import specs

from models.layout import N_ARTICULATORS, N_JOINTS
from sim import events as ev
from sim.caregiver import Caregiver
from sim.dm_control_import import control
from sim.grasping.base import GraspBackend
from sim.physics import CONTROL_SUBSTEPS, PlayroomPhysics
from sim.vocal.voice import Voice

ARM = "arm"
VOICE = "voice"


class PlayroomTask(control.Task):
    """Drives the arm through a grasp backend, the caregiver, and the vocal-tract sensor.

    `vocal_tract` is the voice (sim.vocal.voice.Voice): its `formants(articulators)` gives log2
    (F1, F2) of the current articulators. The `sound` observation is those formants normalised
    as in docs/protocol.md §4 (log2 F1 - 8.5, log2 F2 - 10.25) while the agent speaks, the
    caregiver's word once she speaks, and zeros in silence.
    """

    def __init__(self, grasp: GraspBackend, caregiver: Caregiver, vocal_tract: Voice) -> None:
        super().__init__()
        self.grasp = grasp
        self.caregiver = caregiver
        self.vocal_tract = vocal_tract
        self.movement: str | None = None
        self.step_index = 0
        self.sound = np.zeros(2)
        self._planned_sound: np.ndarray | None = None
        self.step_events: list[ev.Event] = []
        # Whether unobserved movements may run in compiled code (run_steps).
        self.compiled_steps = True

    # dm_control interface -----------------------------------------------------------------
    def initialize_episode(self, physics: PlayroomPhysics) -> None:
        """The start of a trial: the home keyframe (arm at rest, stick at its start)."""
        physics.reset(physics.home_key)
        self.movement = None
        self.sound[:] = 0.0

    def action_spec(self, physics: PlayroomPhysics) -> specs.BoundedArray:
        low = np.concatenate([np.full(N_JOINTS, -np.pi), np.full(N_ARTICULATORS, -1.0)])
        return specs.BoundedArray(
            (N_JOINTS + N_ARTICULATORS,), float, low, -low, name="joint_targets_articulators"
        )

    def before_step(self, action: np.ndarray, physics: PlayroomPhysics) -> None:
        if self.movement is None:
            # Outside a movement the action would be ignored: say so instead of doing nothing.
            raise RuntimeError(
                "the playroom task steps only inside a movement: use Playroom.act (or "
                "task.begin_movement first), or an environment of sim.envs to act one command "
                "a step"
            )
        self.step_index += 1
        # This step's events start as the grasp's own list (a new one at every call).
        if self.movement == ARM:
            self.step_events = self.grasp.before_step(physics, action[:N_JOINTS], self.step_index)
        else:
            self.step_events = self.grasp.during_voice(physics, self.step_index)
            if self._planned_sound is not None:
                self.sound = self._planned_sound[self.step_index - 1]
            else:
                self.sound = self.normalised(self.vocal_tract.formants(action[N_JOINTS:]))
        self.caregiver.before_step(physics, self.step_index)

    def after_step(self, physics: PlayroomPhysics) -> None:
        if self.movement == ARM:
            self.step_events += self.grasp.after_step(physics, self.step_index)

    # A movement's steps, unobserved --------------------------------------------------------
    def run_steps(
        self,
        physics: PlayroomPhysics,
        actions: np.ndarray,
        positions: np.ndarray,
        sound: np.ndarray,
    ) -> list[ev.Event]:
        """Every control step of the movement begun, as the dm_control environment takes them
        but without observations: after step k the tracked positions in positions[k + 1]
        (n + 1, 5, 2) and the sound sensor in sound[k] (n, 2). Returns the steps' events.

        A backend with compiled stepping (the physical one) runs the steps in compiled code
        between the contacts it acts on, where MuJoCo's library is found and `compiled_steps`
        is True (the default); otherwise each step runs here in Python, the reference the
        compiled loop is tested against (tests/sim/test_compiled_steps.py).
        """
        from sim.compiled_steps import AVAILABLE

        sound_known = self.movement == ARM or self._planned_sound is not None
        if self.compiled_steps and AVAILABLE and self.grasp.has_compiled_steps and sound_known:
            return self._run_compiled(physics, actions[:, :N_JOINTS], positions, sound)
        events: list[ev.Event] = []
        for k in range(len(actions)):
            self.before_step(actions[k], physics)
            physics.advance(CONTROL_SUBSTEPS)
            self.after_step(physics)
            physics.write_tracked_positions(positions[k + 1])
            sound[k] = self.sound
            events += self.step_events
        return events

    def _run_compiled(
        self,
        physics: PlayroomPhysics,
        joint_targets: np.ndarray,
        positions: np.ndarray,
        sound: np.ndarray,
    ) -> list[ev.Event]:
        """`run_steps` through the backend's compiled steps, joint_targets (n, 3) the arm's."""
        n = len(joint_targets)
        grasping = self.movement == ARM
        if grasping:
            targets = np.ascontiguousarray(joint_targets)
        else:  # the arm rests; the sound is the planned one, step by step
            targets = np.empty((0, N_JOINTS))
            sound[:] = self._planned_sound
            self.sound[:] = sound[n - 1]
        brought = self.caregiver.path  # None unless she brings a toy
        events: list[ev.Event] = []
        k = self.grasp.run_steps(physics, targets, brought, 0, positions, grasping)
        while k < n:  # a contact the grasp acts on, after step k
            self.step_index = k + 1
            events += self.grasp.after_step(physics, self.step_index)
            physics.write_tracked_positions(positions[k + 1])  # as the grasp left them
            k = self.grasp.run_steps(physics, targets, brought, k + 1, positions, grasping)
        self.step_index = n
        return events

    def get_observation(self, physics: PlayroomPhysics) -> collections.OrderedDict:
        obs = collections.OrderedDict()
        obs["hand"] = physics.hand_position()
        obs["stick_handle"] = physics.stick_handle()
        obs["stick_tip"] = physics.stick_tip()
        obs["toys"] = physics.toy_positions()
        obs["caregiver"] = physics.caregiver_position()
        obs["sound"] = self.sound.copy()
        return obs

    def normalised(self, log2_formants: np.ndarray) -> np.ndarray:
        """(..., 2) log2 Hz formants -> the sound sensor's normalised values."""
        voice = self.vocal_tract.config
        return np.asarray(log2_formants, dtype=float) - (voice.f1_offset, voice.f2_offset)

    def get_reward(self, physics: PlayroomPhysics) -> float:
        # No extrinsic reward: the learner sets its own goals (Model Babbling).
        return 0.0

    # Movements ----------------------------------------------------------------------------
    def begin_movement(
        self, physics: PlayroomPhysics, movement: str, voice_formants: np.ndarray | None = None
    ) -> None:
        """Start a movement. voice_formants: (n_steps, 2) log2 Hz of the planned articulator
        trajectory of a vocal movement. A formant depends only on the articulators of its own
        frame, so the voice computes the whole movement in one vectorised call and the sensor
        reads each step's frame; without it, each step's action is sent through the voice."""
        if movement not in (ARM, VOICE):
            raise ValueError(f"unknown movement {movement!r}: 'arm' or 'voice'")
        self._planned_sound = None if voice_formants is None else self.normalised(voice_formants)
        self.movement = movement
        self.step_index = 0
        self.sound[:] = 0.0
        self.grasp.begin(physics)

    def end_movement(self, physics: PlayroomPhysics) -> None:
        """Drop everything, arm to rest, the caregiver puts down what she carries."""
        self.grasp.release(physics)
        self.caregiver.stop(physics)
        self.grasp.settle(physics)
        self.movement = None
        self.sound[:] = 0.0


class MovementStepper(control.Environment):
    """The dm_control Environment `Playroom` steps a movement through while step observers
    watch (`room.env`): the room's internal stepping, not an environment to act in.

    A step acts only inside a movement the room began (`PlayroomTask.before_step` refuses
    others), and the room does its own bookkeeping around it (iterations, placements, the
    caregiver's words). It is reset once, when the room is built: a later `reset()` would put
    the objects back at the keyframe without the room knowing, so it is refused. To start
    again, build a new `Playroom`; to act one command a step, with resets and episodes, use
    sim/envs/ (a dm_env and a Gymnasium environment).
    """

    def __init__(self, physics: PlayroomPhysics, task: PlayroomTask, n_sub_steps: int) -> None:
        # No time limit: a room's life is as long as its trial; episodes are sim/envs/'s.
        super().__init__(physics, task, n_sub_steps=n_sub_steps, time_limit=float("inf"))
        self._started = False

    def reset(self):
        if self._started:
            raise RuntimeError(
                "room.env is the room's internal stepping and is reset only when the room is "
                "built: build a new Playroom(seed=...), or use sim.envs for an environment "
                "with reset(seed)"
            )
        self._started = True
        return super().reset()
