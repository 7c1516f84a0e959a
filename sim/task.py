"""The playroom as a dm_control task: the room's episode start, its observations (with the vocal
tract as a non-physical sensor) and its action, a movement's joint targets and articulators.

A movement is computed whole by its grasp backend (sim/grasping/, `GraspBackend.simulate`):
no control step of it runs through a dm_control Environment, so the task steps nothing
(`before_step` refuses, with where to go instead). `Playroom` starts its episode with the
task's `initialize_episode`, as dm_control's Environment.reset would, and `normalised` is the
sound sensor: log2 formants as the learner hears them. Environments that act, one command a
step, with `reset` and episodes, are in sim/envs/ (a dm_env and a Gymnasium one).
"""

from __future__ import annotations

import collections

import numpy as np
from dm_env import specs

from models.layout import N_ARTICULATORS, N_JOINTS
from sim.dm_control_import import control
from sim.movement import ARM, VOICE
from sim.physics import PlayroomPhysics
from sim.vocal.voice import Voice

__all__ = ["ARM", "VOICE", "PlayroomTask"]


class PlayroomTask(control.Task):
    """The room's observations and action, and the vocal tract as its sound sensor.

    `vocal_tract` is the voice (sim.vocal.voice.Voice). The `sound` observation is its formants
    normalised as in docs/protocol.md §4 (log2 F1 - 8.5, log2 F2 - 10.25) while the agent
    speaks, the caregiver's word once she speaks, and zeros in silence; between movements, the
    room is silent.
    """

    def __init__(self, vocal_tract: Voice) -> None:
        super().__init__()
        self.vocal_tract = vocal_tract

    def initialize_episode(self, physics: PlayroomPhysics) -> None:
        """The start of a trial: the home keyframe (arm at rest, stick at its start)."""
        physics.reset(physics.home_key)

    def action_spec(self, physics: PlayroomPhysics) -> specs.BoundedArray:
        """A control step's joint targets (rad, relative to rest) and articulators."""
        low = np.concatenate([np.full(N_JOINTS, -np.pi), np.full(N_ARTICULATORS, -1.0)])
        return specs.BoundedArray(
            (N_JOINTS + N_ARTICULATORS,), float, low, -low, name="joint_targets_articulators"
        )

    def before_step(self, action: np.ndarray, physics: PlayroomPhysics) -> None:
        raise RuntimeError(
            "the playroom's movements are computed whole by its grasp backend, not stepped "
            "through dm_control: use Playroom.act, or an environment of sim.envs to act one "
            "command a step"
        )

    def get_observation(self, physics: PlayroomPhysics) -> collections.OrderedDict:
        obs = collections.OrderedDict()
        obs["hand"] = physics.hand_position()
        obs["stick_handle"] = physics.stick_handle()
        obs["stick_tip"] = physics.stick_tip()
        obs["toys"] = physics.toy_positions()
        obs["caregiver"] = physics.caregiver_position()
        obs["sound"] = np.zeros(2)  # silence between movements
        return obs

    def normalised(self, log2_formants: np.ndarray) -> np.ndarray:
        """(..., 2) log2 Hz formants -> the sound sensor's normalised values."""
        voice = self.vocal_tract.config
        return np.asarray(log2_formants, dtype=float) - (voice.f1_offset, voice.f2_offset)

    def get_reward(self, physics: PlayroomPhysics) -> float:
        # No extrinsic reward: the learner sets its own goals (Model Babbling).
        return 0.0
