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
from sim.envs import goals, motor_spaces
from sim.envs.gym_env import SPACE_DTYPE, PlayroomGymEnv
from sim.envs.rendering import DEFAULT_SIZE
from sim.envs.versions import GOAL_MOVEMENTS
from sim.grasping.names import DEFAULT_GRASP
from sim.vocal.config import DEFAULT_VOICE, VoiceConfig

DictObs = dict[str, Any]
# The reset option that sets the desired goal instead of drawing one.
DESIRED_GOAL = "desired_goal"
SPARSE, DENSE = "sparse", "dense"
REWARDS = (SPARSE, DENSE)


class PlayroomGoalEnv(gymnasium.Env[DictObs, np.ndarray]):
    """## Description

    The playroom of `Playroom-v1` (PlayroomGymEnv: the same room, stepping, seeds and rendering)
    with one of the study's goals to reach: an object brought to a point of the table, or a word
    said. Each goal space is one of the study's sensorimotor models (docs/protocol.md §8), whose
    goals its Model Babbling learner sets itself; here the environment draws them. `goal`
    chooses it:

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

    Box(-1, 1, float32) of the motor space `motor` (sim/envs/motor_spaces.py):

    | motor   | shape | the action                                                        |
    |---------|-------|-------------------------------------------------------------------|
    | "arm"   | (21,) | an arm command, PlayroomGymEnv's `a[1:22]`                        |
    | "voice" | (28,) | a voice command, PlayroomGymEnv's `a[22:50]`                      |
    | "both"  | (50,) | PlayroomGymEnv's (`a[0] < 0`: the arm command, else the voice)    |

    By default each goal gets the space that reaches it: the arm for "hand", "stick" and the
    toys (a toy within reach of the hand or a held stick), the voice for "word". The other
    space's numbers would move nothing toward the goal, and a learner relabelling its goals
    (hindsight) would be rewarded for leaving the object where it lies.

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
    vocal tract; `info["desired_word"]` names it. A drawn goal is never already met: one within
    the tolerance of what is achieved at rest (the stick's handle where it lies, a toy where it
    was placed, the hand at rest) is drawn again, until one is not (rejection sampling: the
    placement rule with the goals met at rest cut out; sim/envs/goals.py `draw_unmet`).

    `info` holds PlayroomGymEnv's (motor_space, events, event_counts, iteration, seed), the
    goal's `ring` ("near": within the arm's reach, 0.5 m, where the hand takes an object; "far":
    beyond, where only a held stick's end does; None for "word") and, after a step,
    `is_success` (1.0 if the goal is reached, else 0.0).

    ## Rewards

    `reward="sparse"` (the default), as Gymnasium-Robotics' Fetch: 0.0 when the achieved goal
    lies within the goal's tolerance of the desired one (Euclidean distance strictly less), else
    -1.0. `reward="dense"`, as Fetch's dense variants: minus the distance. The tolerance is the
    study's own: `WorldConfig.grasp_distance` (0.1 m, within which its hand takes an object) for
    positions; `VoiceConfig.recognition_distance` (0.4, within which its caregiver recognises a
    word) for sounds; `is_success` is the goal within it, whatever the reward.
    `compute_reward(achieved_goal, desired_goal, info)` gives the same reward for one goal or a
    batch (shape (n, goal_dim)), as hindsight relabelling calls it; `info` is not read.

    ## Starting State

    `reset(seed=s)` builds the room of seed s (PlayroomGymEnv's, the world of `playroom run
    --seed s`: its toys placed in the study's rings, the stick at its start, the arm at rest)
    and draws a desired goal; `reset()` a room of a seed drawn from `np_random`;
    `reset(options={"desired_goal": g})` sets the goal to g (of the goal's shape, within its
    bound) instead, to evaluate chosen goals: taken as given, met at rest or not.

    ## Episode End

    Terminated after `movements` movements (1 by default: one movement is what the study gives
    each goal, §9, and each test, §10), reached or not; never truncated. Then `step` wants a
    `reset`, as it does before the first one. By the world's rules one movement can reach a goal
    of the hand, the handle or a word, and a toy's goal when the toy lies within reach of the
    hand or a held stick; a toy in ring 3 needs the caregiver first (a name or two, each
    bringing it 39.5% of her way), then the arm. Within a few movements the toys are never
    re-placed (every 20 iterations), so a goal keeps its meaning for the whole episode. A goal
    reached may be lost again by a later movement (the arm returns to rest after every movement
    and drops what it holds): `compute_terminated` is False for every goal, the end being the
    count of movements, not the goals.

    The registered ids are made without Gymnasium's wrappers (no `max_episode_steps`, no order
    enforcing or passive checker: sim/envs/versions.py `GOAL_REGISTRATION`), so that
    `gymnasium.make(id)` is this environment itself, which stable-baselines3's `check_env` and
    `HerReplayBuffer` take whole. Give `movements=N`, not `max_episode_steps=N`: the latter adds
    Gymnasium's TimeLimit, whose wrapper has no `compute_reward` (pass `env.unwrapped` then).

    ## Arguments

    `goal` ("hand", "stick", "toy1", "toy2", "toy3" or "word"); `motor` ("arm", "voice", "both";
    None: the goal's own, above); `movements` (a positive integer, 1); `reward` ("sparse" or
    "dense"); then PlayroomGymEnv's, with their defaults: `grasp` ("kinematic" or "physical"),
    `preset` or `config`, `voice`, `voice_config`, `render_mode` ("rgb_array", "rgb_array_list":
    each movement's frames, or "human"), `render_size`, `camera`. Each is refused in one line
    when it names nothing.

    ## Version History

    * v1: PlayroomHandGoal-v1, PlayroomStickGoal-v1, PlayroomToyGoal-v1, PlayroomWordGoal-v1
      and PlayroomHandGoalPhysical-v1, PlayroomStickGoalPhysical-v1,
      PlayroomToyGoalPhysical-v1, PlayroomWordGoalPhysical-v1 (v0 is refused in their favour):
      an action of the goal's own motor space (`motor`: arm (21,) for the position goals, voice
      (28,) for "word", or both (50,)); episodes of `movements` movements (1), then terminated,
      not truncated after 3; `reward="dense"`; desired goals never already met at reset; the
      goal's `ring` in `info`; registered without Gymnasium's wrappers (no
      `max_episode_steps`), so that stable-baselines3's `check_env` takes `gymnasium.make(id)`
      whole; `iterations` replaced by `movements`.
    * v0: initial version: PlayroomHandGoal-v0, PlayroomStickGoal-v0, PlayroomToyGoal-v0
      (toy1), PlayroomWordGoal-v0 (the kinematic grasp), and each with the physical grasp,
      PlayroomHandGoalPhysical-v0, PlayroomStickGoalPhysical-v0, PlayroomToyGoalPhysical-v0,
      PlayroomWordGoalPhysical-v0; the world of Playroom-v1; PlayroomGymEnv's 50 numbers for
      every goal; episodes truncated after 3 movements by TimeLimit; goals met at rest drawn as
      any other.
    """

    def __init__(
        self,
        goal: str = "hand",
        *,
        motor: str | None = None,
        movements: int = GOAL_MOVEMENTS,
        reward: str = SPARSE,
        grasp: str = DEFAULT_GRASP,
        preset: str | None = None,
        config: WorldConfig | None = None,
        voice: str | None = None,
        voice_config: VoiceConfig = DEFAULT_VOICE,
        render_mode: str | None = None,
        render_size: tuple[int, int] = DEFAULT_SIZE,
        camera: str = "top",
    ) -> None:
        self.goal = goals.checked_goal(goal)
        self.motor = motor_spaces.checked_motor(motor, self.goal)
        self.movements = _checked_movements(movements)
        if reward not in REWARDS:
            raise ValueError(f"unknown reward {reward!r}: one of {', '.join(REWARDS)}")
        self.reward_type = reward
        self.playroom = PlayroomGymEnv(
            grasp, preset, config, voice, voice_config, None, render_mode, render_size, camera
        )
        self.metadata = self.playroom.metadata
        self.render_mode = self.playroom.render_mode
        room = self.playroom.movement_env.room
        self.tolerance = goals.tolerance(self.goal, room.config, room.vocal_tract.config)
        high = np.full(self.goal.dim, goals.bound(self.goal, room), dtype=SPACE_DTYPE)
        self.goal_space = spaces.Box(-high, high, dtype=SPACE_DTYPE)
        size = motor_spaces.action_size(self.motor)
        self.action_space = spaces.Box(-1.0, 1.0, (size,), SPACE_DTYPE)
        self.observation_space = spaces.Dict(
            {
                "observation": self.playroom.observation_space,
                "achieved_goal": self.goal_space,
                DESIRED_GOAL: spaces.Box(-high, high, dtype=SPACE_DTYPE),
            }
        )
        self._desired = np.zeros(self.goal.dim, dtype=SPACE_DTYPE)
        self._ring: str | None = None
        self._left: int | None = None  # movements left in the episode; None before a reset

    def reset(
        self, *, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[DictObs, dict[str, Any]]:
        given = self._given_goal(options)
        # The room's reset checks the seed first (a one-line ValueError).
        observation, info = self.playroom.reset(seed=seed)
        super().reset(seed=seed)
        room = self.playroom.movement_env.room
        if given is None:
            desired, word = self._drawn_goal(room)
            if word is not None:
                info["desired_word"] = word
        else:
            desired = given
        self._desired = desired.astype(SPACE_DTYPE)
        self._ring = goals.ring_of(self.goal, self._desired, room.config)
        self._left = self.movements
        info["ring"] = self._ring
        return self._observation(observation, goals.achieved_at_rest(self.goal, room)), info

    def step(self, action: np.ndarray) -> tuple[DictObs, float, bool, bool, dict[str, Any]]:
        if not self._left:
            raise RuntimeError(
                "call reset() first"
                if self._left is None
                else f"the episode ended after its {self.movements} movement(s): call reset()"
            )
        flat = motor_spaces.flat_action(self.motor, action)
        observation, _, _, _, info = self.playroom.step(flat)
        self._left -= 1
        feedback = self.playroom.movement_env.last_feedback
        assert feedback is not None  # a step after reset acts
        achieved = goals.achieved_after(self.goal, feedback.s, info["motor_space"])
        obs = self._observation(observation, achieved)
        # From the observation's float32 goals, as compute_reward sees them from a buffer.
        reward = float(self.compute_reward(obs["achieved_goal"], obs["desired_goal"], info))
        reached = goals.distance(obs["achieved_goal"], obs["desired_goal"]) < self.tolerance
        info["is_success"] = float(reached)
        info["ring"] = self._ring
        return obs, reward, self._left == 0, False, info

    def compute_reward(
        self, achieved_goal: np.ndarray, desired_goal: np.ndarray, info: Any = None
    ) -> np.ndarray:
        """Sparse: 0.0 where the achieved goal is within the tolerance of the desired one, else
        -1.0; dense: minus the distance. One reward for goals of shape (goal_dim,), one per row
        for (n, goal_dim)."""
        d = goals.distance(achieved_goal, desired_goal)
        if self.reward_type == DENSE:
            return -d
        return (d < self.tolerance).astype(np.float64) - 1.0

    def compute_terminated(
        self, achieved_goal: np.ndarray, desired_goal: np.ndarray, info: Any = None
    ) -> np.ndarray:
        """No goal ends an episode (its count of movements does: see the docstring): False for
        each goal."""
        return np.zeros(goals.distance(achieved_goal, desired_goal).shape, dtype=bool)

    def compute_truncated(
        self, achieved_goal: np.ndarray, desired_goal: np.ndarray, info: Any = None
    ) -> np.ndarray:
        """Never truncated: False for each goal."""
        return self.compute_terminated(achieved_goal, desired_goal, info)

    def render(self) -> Any:
        """PlayroomGymEnv's frames of the room (its `render`)."""
        return self.playroom.render()

    def close(self) -> None:
        self.playroom.close()

    def _drawn_goal(self, room: Any) -> tuple[np.ndarray, str | None]:
        """A desired goal drawn from `np_random`, never met at rest (and a word's name)."""
        return goals.draw_unmet(self.goal, room, self.np_random, self.tolerance)

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


def _checked_movements(movements: object) -> int:
    if isinstance(movements, bool) or not isinstance(movements, int | np.integer) or movements < 1:
        raise ValueError(f"movements must be a positive integer, got {movements!r}")
    return int(movements)


def make_goal_registered(**kwargs: Any) -> PlayroomGoalEnv:
    """The environment of a registered goal id (sim/envs/versions.py), as `gymnasium.make`
    builds it: the environment itself, unwrapped. An episode's length is `movements`, so
    `iterations` (v0's) is refused in one line."""
    if "iterations" in kwargs:
        raise ValueError(
            "a goal episode's length is its movements: give "
            f"movements={kwargs['iterations']!r}, not iterations"
        )
    return PlayroomGoalEnv(**kwargs)
