"""Environments a learner other than this project's plugs into, at the level of the study's
iterations (one step = one arm or voice command, as the study's agent acts):

- `PlayroomMovementEnv` (sim/envs/dm_env_movement.py): a dm_env environment, dict action and
  observation specs;
- `PlayroomGymEnv` (sim/envs/gym_env.py): the same world as a Gymnasium environment with Box
  spaces, registered when this package is imported as "Playroom-v1" and its variants
  (sim/envs/versions.py: "PlayroomPhysical-v1", "PlayroomDiva-v1"), so that
  `gymnasium.make("sim.envs:Playroom-v1", grasp="physical")` works without importing it first;
- `PlayroomGoalEnv` (sim/envs/goal_env.py): the same world with one of the study's goals, in
  Gymnasium-Robotics' goal-conditioned form (for hindsight relabelling), registered as
  "PlayroomHandGoal-v1" and its siblings (sim/envs/versions.py, `GOAL_VARIANTS`); and
  `PlayroomToysGoalEnv` (sim/envs/toys_goal_env.py), the three toys in one goal environment,
  the toy part of the goal ("PlayroomToysGoal-v1", `TOYS_GOAL_VARIANTS`).

Both check actions with one check (sim/envs/actions.py); the Gymnasium one renders
(sim/envs/rendering.py; a GL library is loaded only for a render mode). Both build each
episode's `Playroom` from its seed, and draw frames from its movements' traces
(sim/movement.py). The classes load on first use, so that registering costs no MuJoCo.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from sim.process_environment import environment_kept

# Gymnasium sets PYGAME_HIDE_SUPPORT_PROMPT when first imported; importing sim changes no
# environment variable, so it is put back.
with environment_kept():
    from gymnasium.envs.registration import register, registry

from sim.envs.versions import (
    DIVA_ID,
    ENTRY_POINT,
    GOAL_ENTRY_POINT,
    GOAL_REGISTRATION,
    GOAL_VARIANTS,
    GYM_ID,
    PHYSICAL_ID,
    STUDY_ITERATIONS,
    TOYS_GOAL_ENTRY_POINT,
    TOYS_GOAL_VARIANTS,
    VARIANTS,
)

if TYPE_CHECKING:
    from sim.envs.dm_env_movement import PlayroomMovementEnv
    from sim.envs.goal_env import PlayroomGoalEnv
    from sim.envs.gym_env import PlayroomGymEnv

for _id, _kwargs in VARIANTS.items():
    if _id not in registry:  # a second import (importlib.reload) registers nothing twice
        # The episode is the study's run, which Gymnasium's TimeLimit ends (a truncation), so
        # that `spec.max_episode_steps` says how long it is; `max_episode_steps=N` shortens it.
        register(
            id=_id, entry_point=ENTRY_POINT, max_episode_steps=STUDY_ITERATIONS, kwargs=_kwargs
        )
for _id, _kwargs in GOAL_VARIANTS.items():
    if _id not in registry:
        # A goal episode is ended by the environment itself after its movements, and
        # `gymnasium.make` returns the environment unwrapped (GOAL_REGISTRATION's comment).
        register(id=_id, entry_point=GOAL_ENTRY_POINT, kwargs=_kwargs, **GOAL_REGISTRATION)
for _id, _kwargs in TOYS_GOAL_VARIANTS.items():
    if _id not in registry:
        register(id=_id, entry_point=TOYS_GOAL_ENTRY_POINT, kwargs=_kwargs, **GOAL_REGISTRATION)

__all__ = [
    "DIVA_ID",
    "GOAL_VARIANTS",
    "GYM_ID",
    "PHYSICAL_ID",
    "TOYS_GOAL_VARIANTS",
    "PlayroomGoalEnv",
    "PlayroomGymEnv",
    "PlayroomMovementEnv",
]


def __getattr__(name: str) -> Any:
    if name == "PlayroomMovementEnv":
        from sim.envs import dm_env_movement

        return dm_env_movement.PlayroomMovementEnv
    if name == "PlayroomGoalEnv":
        from sim.envs import goal_env

        return goal_env.PlayroomGoalEnv
    if name == "PlayroomGymEnv":
        from sim.envs import gym_env

        return gym_env.PlayroomGymEnv
    raise AttributeError(f"module 'sim.envs' has no attribute {name!r}")
