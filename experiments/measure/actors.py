"""Who is tested: the measures (evaluation.py's competence, study_measure.py's tests) set a test,
then ask an actor what it does; everything else (the scene, the goal, the random reference, the
error) is the measure's own, the same whoever acts. An actor answers `choose(toy, context, goal)`
with a `Choice`: the motor space and command to play, and what it consulted to choose.

Actors here:
- `LearnerActor`: the Model Babbling agent (learner/agent.py) as the project's measure asks it
  (docs/protocol.md §10): the arm or the voice model of the toy, whichever has the nearer
  experience of (context, goal), inverted without exploration noise; the arm at rest when
  neither model has data;
- study_measure.py's `StudyLearnerActor`: the same agent asked as the study's code asked it;
- policy_actor.py's `PolicyActor`: a goal-conditioned policy of sim/envs' goal environments
  (a reinforcement-learning baseline), asked as those environments ask it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Protocol

import numpy as np

from learner.agent import Agent
from models.layout import ARM_DIM


@dataclass(frozen=True)
class Choice:
    """What an actor plays in a test, and what it consulted: the distances of (context, goal)
    to the nearest experience of the toy's arm and voice models (NaN for an actor without such
    memories), and `untrained`, whether it had nothing to choose from (the arm at rest)."""

    motor_space: str
    command: np.ndarray
    arm_nn_distance: float = math.nan
    voice_nn_distance: float = math.nan
    untrained: bool = False


class Actor(Protocol):
    def choose(self, toy: int, context: np.ndarray, goal: np.ndarray) -> Choice:
        """The command for toy `toy` (1-3) to follow the 10D `goal` trajectory from the scene
        whose context (10,) is `context`. It only reads: the measure owns the room."""
        ...


class LearnerActor:
    """The Model Babbling agent as the project's measure asks it (see the module's docstring).
    The agent is only read: `exploit` draws nothing from its generator."""

    def __init__(self, agent: Agent) -> None:
        self.agent = agent

    def choose(self, toy: int, context: np.ndarray, goal: np.ndarray) -> Choice:
        agent = self.agent
        arm_model, voice_model = agent.toy_models(toy)
        d_arm = agent.nearest_distance(arm_model, context, goal)
        d_voice = agent.nearest_distance(voice_model, context, goal)
        space, model = ("arm", arm_model) if d_arm <= d_voice else ("voice", voice_model)
        untrained = not np.isfinite(min(d_arm, d_voice))
        # A toy never moved has no model to invert: the arm stays at rest.
        command = np.zeros(ARM_DIM) if untrained else agent.exploit(model, context, goal)
        return Choice(space, command, d_arm, d_voice, untrained)
