"""The playroom with a task: goal-conditioned Gymnasium environments in Gymnasium-Robotics'
convention (a Dict observation of `observation`, `achieved_goal`, `desired_goal`; a vectorised
`compute_reward`), so that hindsight relabelling (stable-baselines3's HerReplayBuffer) trains on
the study's own goals. `PlayroomGoalEnv`'s docstring says everything a user needs; the goals
themselves are sim/envs/goals.py; the room is stepped by `PlayroomGymEnv`, which this wraps.
"""

from __future__ import annotations

from typing import Any

import gymnasium
import numpy as np
from gymnasium import spaces

from sim.config import WorldConfig
from sim.envs import goals
from sim.envs.gym_env import SPACE_DTYPE, PlayroomGymEnv
from sim.envs.rendering import DEFAULT_SIZE
from sim.envs.versions import GOAL_EPISODE_STEPS
from sim.grasping.names import DEFAULT_GRASP
from sim.vocal.config import DEFAULT_VOICE, VoiceConfig

DictObs = dict[str, Any]
# The reset option that sets the desired goal instead of drawing one.
DESIRED_GOAL = "desired_goal"


class PlayroomGoalEnv(gymnasium.Env[DictObs, np.ndarray]):
    """## Description

    The playroom of `Playroom-v1` (PlayroomGymEnv: the same room, actions, stepping, seeds and
    rendering) with one of the study's goals to reach: an object brought to a point of the
    table, or a word said. Each goal space is one of the study's sensorimotor models
    (docs/protocol.md §8), whose goals its Model Babbling learner sets itself; here the
    environment draws them. `goal` chooses it:

    | goal             | achieved_goal (after a movement)                 | study's model      |
    |------------------|--------------------------------------------------|--------------------|
    | "hand"           | hand x, y at the last sample (step 50)           | 1: arm -> hand     |
    | "stick"          | stick handle x, y at the last sample             | 2: arm -> stick    |
    | "toy1" - "toy3"  | the toy's x, y at the last sample                | 3-5 arm, 7-9 voice |
    | "word"           | the agent's own sound: 5 F1, then 5 F2 features  | 10: voice -> sound |

    The handle is what the study senses of the stick. A toy is moved by the arm (the hand or a
    held stick) or brought by the caregiver, who moves a toy whose name she recognises 39.5%
    of the way toward her midpoint with the arm's base. After an arm movement the agent's own
    sound is silence (zeros), not the caregiver's word that the observation's sound block holds.
    Before the first movement the achieved goal is where the object lies (silence for "word").

    ## Action Space

    Box(-1, 1, (50,), float32): PlayroomGymEnv's (`a[0] < 0`: the arm command `a[1:22]`, else
    the voice command `a[22:50]`).

    ## Observation Space

    Dict of float32 Boxes:

    | Key           | Shape   | Bound | What                                                   |
    |---------------|---------|-------|--------------------------------------------------------|
    | observation   | (70,)   | table | PlayroomGymEnv's: the context, the last feedback       |
    | achieved_goal | (2,)    | 1.3   | position goals: x, y in m (table's half-size)          |
    | desired_goal  | (2,)    | 1.3   | position goals: the point to bring the object to       |
    | achieved_goal | (10,)   | 4     | "word": sound features (log2 Hz less the offsets)      |
    | desired_goal  | (10,)   | 4     | "word": the features of one of the caregiver's words   |

    Desired goals are drawn at `reset` from the environment's `np_random`, as the study draws
    placements (a ring with equal chance, a radius uniform in it, an angle uniform): the hand's
    and the handle's within the arm's reach, [0, 0.5] m; a toy's in rings 1 and 2 of the study's
    placements, [0, 0.5] and [0.5, 0.75] m, where the hand or a held stick takes it (ring 3 is
    left out: only the caregiver reaches it). A word is one of the caregiver's six (the toys'
    three names and three distractors) with equal chance, its perfect trajectory in the room's
    vocal tract; `info["desired_word"]` names it.

    `info` holds PlayroomGymEnv's (motor_space, events, event_counts, iteration, seed) and,
    after a step, `is_success` (1.0 if the goal is reached, else 0.0).

    ## Rewards

    Sparse, as Gymnasium-Robotics' Fetch: 0.0 when the achieved goal lies within the goal's
    tolerance of the desired one (Euclidean distance strictly less), else -1.0. The tolerance
    is the study's own: `WorldConfig.grasp_distance` (0.1 m, within which its hand takes an
    object) for positions; `VoiceConfig.recognition_distance` (0.4, within which its caregiver
    recognises a word) for sounds. `compute_reward(achieved_goal, desired_goal, info)` gives
    the same reward for one goal or a batch (shape (n, goal_dim)), as hindsight relabelling
    calls it; `info` is not read. `compute_terminated` and `compute_truncated` are False.

    ## Starting State

    `reset(seed=s)` builds the room of seed s (PlayroomGymEnv's, the world of `playroom run
    --seed s`: its toys placed in the study's rings, the stick at its start, the arm at rest)
    and draws a desired goal; `reset()` a room of a seed drawn from `np_random`;
    `reset(options={"desired_goal": g})` sets the goal to g (of the goal's shape, within its
    bound) instead, to evaluate chosen goals.

    ## Episode End

    Never terminated: as in Fetch, a goal reached may be lost again (the arm returns to rest
    after every movement and drops what it holds). Truncated after 3 movements (the registered
    ids' `max_episode_steps`, or `iterations` made directly). One movement is what the study
    gives each goal (§9) and each test (§10), and by the world's rules it can reach a goal of
    the hand, the handle or a word, and a toy's goal when the toy lies within reach of the hand
    or a held stick; a toy in ring 3 needs the caregiver first (a name or two, each bringing it
    39.5% of her way), then the arm. Within 3 movements the toys are never re-placed (every 20
    iterations), so a goal keeps its meaning for the whole episode.

    ## Arguments

    `goal` ("hand", "stick", "toy1", "toy2", "toy3" or "word"), then PlayroomGymEnv's, with
    their defaults: `grasp` ("kinematic" or "physical"), `preset` or `config`, `voice`,
    `voice_config`, `iterations` (3; refused by `make`), `render_mode`, `render_size`, `camera`.

    ## Version History

    * v0: initial version: PlayroomHandGoal-v0, PlayroomStickGoal-v0, PlayroomToyGoal-v0
      (toy1), PlayroomWordGoal-v0 (the kinematic grasp), and each with the physical grasp,
      PlayroomHandGoalPhysical-v0, PlayroomStickGoalPhysical-v0, PlayroomToyGoalPhysical-v0,
      PlayroomWordGoalPhysical-v0; the world of Playroom-v1.
    """

    def __init__(
        self,
        goal: str = "hand",
        grasp: str = DEFAULT_GRASP,
        preset: str | None = None,
        config: WorldConfig | None = None,
        voice: str | None = None,
        voice_config: VoiceConfig = DEFAULT_VOICE,
        iterations: int | None = GOAL_EPISODE_STEPS,
        render_mode: str | None = None,
        render_size: tuple[int, int] = DEFAULT_SIZE,
        camera: str = "top",
    ) -> None:
        self.goal = goals.checked_goal(goal)
        self.playroom = PlayroomGymEnv(
            grasp, preset, config, voice, voice_config, iterations, render_mode, render_size,
            camera,
        )  # fmt: skip
        self.metadata = self.playroom.metadata
        self.render_mode = self.playroom.render_mode
        room = self.playroom.movement_env.room
        self.tolerance = goals.tolerance(self.goal, room.config, room.vocal_tract.config)
        high = np.full(self.goal.dim, goals.bound(self.goal, room), dtype=SPACE_DTYPE)
        self.goal_space = spaces.Box(-high, high, dtype=SPACE_DTYPE)
        self.action_space = self.playroom.action_space
        self.observation_space = spaces.Dict(
            {
                "observation": self.playroom.observation_space,
                "achieved_goal": self.goal_space,
                DESIRED_GOAL: spaces.Box(-high, high, dtype=SPACE_DTYPE),
            }
        )
        self._desired = np.zeros(self.goal.dim, dtype=SPACE_DTYPE)

    def reset(
        self, *, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[DictObs, dict[str, Any]]:
        given = self._given_goal(options)
        # The room's reset checks the seed first (a one-line ValueError).
        observation, info = self.playroom.reset(seed=seed)
        super().reset(seed=seed)
        room = self.playroom.movement_env.room
        desired, word = goals.draw_desired(self.goal, room, self.np_random)
        self._desired = (desired if given is None else given).astype(SPACE_DTYPE)
        if word is not None and given is None:
            info["desired_word"] = word
        return self._observation(observation, goals.achieved_at_rest(self.goal, room)), info

    def step(self, action: np.ndarray) -> tuple[DictObs, float, bool, bool, dict[str, Any]]:
        observation, _, terminated, truncated, info = self.playroom.step(action)
        feedback = self.playroom.movement_env.last_feedback
        assert feedback is not None  # a step after reset acts
        achieved = goals.achieved_after(self.goal, feedback.s, info["motor_space"])
        obs = self._observation(observation, achieved)
        # From the observation's float32 goals, as compute_reward sees them from a buffer.
        reward = float(self.compute_reward(obs["achieved_goal"], obs["desired_goal"], info))
        info["is_success"] = float(reward == 0.0)
        return obs, reward, terminated, truncated, info

    def compute_reward(
        self, achieved_goal: np.ndarray, desired_goal: np.ndarray, info: Any = None
    ) -> np.ndarray:
        """0.0 where the achieved goal is within the tolerance of the desired one, else -1.0:
        one reward for goals of shape (goal_dim,), one per row for (n, goal_dim)."""
        within = goals.distance(achieved_goal, desired_goal) < self.tolerance
        return within.astype(np.float64) - 1.0

    def compute_terminated(
        self, achieved_goal: np.ndarray, desired_goal: np.ndarray, info: Any = None
    ) -> np.ndarray:
        """Never terminated (see the docstring): False for each goal."""
        return np.zeros(goals.distance(achieved_goal, desired_goal).shape, dtype=bool)

    def compute_truncated(
        self, achieved_goal: np.ndarray, desired_goal: np.ndarray, info: Any = None
    ) -> np.ndarray:
        """No truncation of the goals' own (the episode's length truncates): False for each."""
        return self.compute_terminated(achieved_goal, desired_goal, info)

    def render(self) -> np.ndarray | None:
        """PlayroomGymEnv's frame of the room (its `render`)."""
        return self.playroom.render()

    def close(self) -> None:
        self.playroom.close()

    def _given_goal(self, options: dict[str, Any] | None) -> np.ndarray | None:
        """The desired goal `options` gives, checked against the goal space (a one-line
        ValueError), or None."""
        options = dict(options or {})
        given = options.pop(DESIRED_GOAL, None)
        if options:
            raise ValueError(f"reset takes only the option {DESIRED_GOAL!r}, got {sorted(options)}")
        if given is None:
            return None
        try:
            goal = np.asarray(given, dtype=np.float64)
        except (TypeError, ValueError):
            raise ValueError(f"{DESIRED_GOAL} must be real numbers, got {given!r}") from None
        space = self.goal_space
        if goal.shape != space.shape:
            raise ValueError(f"{DESIRED_GOAL} must have shape {space.shape}, got {goal.shape}")
        if goal.astype(SPACE_DTYPE) not in space:
            raise ValueError(
                f"{DESIRED_GOAL} must be finite and within +-{space.high[0]:g}, got {goal.tolist()}"
            )
        return goal

    def _observation(self, observation: np.ndarray, achieved: np.ndarray) -> DictObs:
        return {
            "observation": observation,
            "achieved_goal": achieved.astype(SPACE_DTYPE),
            "desired_goal": self._desired.copy(),
        }


def make_goal_registered(**kwargs: Any) -> PlayroomGoalEnv:
    """The environment of a registered goal id (sim/envs/versions.py), as `gymnasium.make`
    builds it: TimeLimit ends its episodes at `max_episode_steps`, so it refuses `iterations`
    (one-line ValueError)."""
    if "iterations" in kwargs:
        raise ValueError(
            "with gymnasium.make the episode's length is max_episode_steps "
            f"({GOAL_EPISODE_STEPS} by default): give max_episode_steps={kwargs['iterations']!r}, "
            "not iterations"
        )
    return PlayroomGoalEnv(iterations=None, **kwargs)
