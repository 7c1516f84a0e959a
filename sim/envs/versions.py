"""The Gymnasium ids `import sim.envs` registers, and the episode length they declare: names and
numbers only, so that registering imports no MuJoCo (sim/envs/__init__.py).

Each id is one world, versioned as Gymnasium versions its own environments: a change that can
change what a learner sees or gets (spaces, dynamics, episode length, rendering) makes a new
version, and an id no longer registered is refused by Gymnasium with the versions that are
(PlayroomGymEnv's docstring holds the history).
"""

from __future__ import annotations

from typing import Any

# One episode is one of the study's runs (docs/protocol.md §1, "Run length"); the same number as
# `playroom run --iterations`'s default, which sim cannot import.
STUDY_ITERATIONS = 80000

VERSION = 1
GYM_ID = f"Playroom-v{VERSION}"
PHYSICAL_ID = f"PlayroomPhysical-v{VERSION}"
DIVA_ID = f"PlayroomDiva-v{VERSION}"
# id -> the keyword arguments its world is made with (the rest are PlayroomGymEnv's defaults:
# the kinematic grasp, the study's preset, VocalTractLab's voice). Names as the command line's
# `--grasp` and `--voice` take them.
VARIANTS: dict[str, dict[str, Any]] = {
    GYM_ID: {},
    PHYSICAL_ID: {"grasp": "physical"},
    # DIVA's map is the user's data (`playroom voice-data diva PATH` installs it).
    DIVA_ID: {"voice": "diva"},
}
ENTRY_POINT = "sim.envs.gym_env:make_registered"

# The goal-conditioned ids (sim/envs/goal_env.py): the world of the ids above with one of the
# study's goals. Their own versions (PlayroomGoalEnv's docstring holds the history): a new
# VERSION of the world makes a new one of these too.
GOAL_VERSION = 1
# Movements per goal episode by default: one, as the study gives each goal one movement
# (docs/protocol.md §9), the episode then terminated. The environment counts them itself (no
# `max_episode_steps`: see GOAL_REGISTRATION).
GOAL_MOVEMENTS = 1
# id -> its goal and grasp backend: each goal with the kinematic grasp, and "Physical" with the
# physical one. The toy ids bring toy1 (`goal="toy2"` or "toy3" for another).
GOAL_VARIANTS: dict[str, dict[str, Any]] = {
    f"Playroom{name}Goal{suffix}-v{GOAL_VERSION}": {"goal": goal, **grasp}
    for name, goal in (("Hand", "hand"), ("Stick", "stick"), ("Toy", "toy1"), ("Word", "word"))
    for suffix, grasp in (("", {}), ("Physical", {"grasp": "physical"}))
}
GOAL_ENTRY_POINT = "sim.envs.goal_env:make_goal_registered"
# One goal environment for the three toys, the toy drawn each episode and part of the goal
# (sim/envs/toys_goal_env.py, its docstring holds the history): one policy for the three toys,
# as the race with Model Babbling wants (docs/rl-race.md). Registered as the goal ids are.
TOYS_GOAL_VERSION = 1
TOYS_GOAL_VARIANTS: dict[str, dict[str, Any]] = {
    f"PlayroomToysGoal{suffix}-v{TOYS_GOAL_VERSION}": grasp
    for suffix, grasp in (("", {}), ("Physical", {"grasp": "physical"}))
}
TOYS_GOAL_ENTRY_POINT = "sim.envs.toys_goal_env:make_toys_goal_registered"
# How the goal ids are registered: without Gymnasium's wrappers (TimeLimit, OrderEnforcing,
# PassiveEnvChecker), so that `gymnasium.make(goal_id)` is the environment itself. Gymnasium
# 1.x's wrappers forward no attribute, and stable-baselines3 finds a goal environment on
# `env.unwrapped` but calls `compute_reward` on the wrapper it was given ('TimeLimit' object has
# no attribute 'compute_reward'). The environment ends its own episodes and refuses a step
# before `reset` or after the end, what TimeLimit and OrderEnforcing did; the tests run
# Gymnasium's checker in place of the passive one.
GOAL_REGISTRATION: dict[str, Any] = {"order_enforce": False, "disable_env_checker": True}
