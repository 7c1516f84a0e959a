"""Environments a learner other than this project's plugs into, at the level of the study's
iterations (one step = one arm or voice command, as the study's agent acts):

- `PlayroomMovementEnv` (sim/envs/dm_env_movement.py): a dm_env environment, dict action and
  observation specs;
- `PlayroomGymEnv` (sim/envs/gym_env.py): the same world as a Gymnasium environment with Box
  spaces, registered as "Playroom-v0" when this package is imported, so that
  `gymnasium.make("sim.envs:Playroom-v0", grasp="physical")` works without importing it first.

Both check actions with one check (sim/envs/actions.py); the Gymnasium one renders
(sim/envs/rendering.py; a GL library is loaded only for a render mode). Both build each
episode's `Playroom` from its seed; `room.env`, the room's own dm_control Environment, is only
its internal stepping (sim/task.py, `MovementStepper`). The classes load
on first use, so that registering costs no MuJoCo.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from sim import environment_kept

# Gymnasium sets PYGAME_HIDE_SUPPORT_PROMPT when first imported; importing sim changes no
# environment variable, so it is put back.
with environment_kept():
    from gymnasium.envs.registration import register, registry

if TYPE_CHECKING:
    from sim.envs.dm_env_movement import PlayroomMovementEnv
    from sim.envs.gym_env import PlayroomGymEnv

GYM_ID = "Playroom-v0"

if GYM_ID not in registry:  # a second import (importlib.reload) registers nothing twice
    # No max_episode_steps: the environment truncates itself after its `iterations`.
    register(id=GYM_ID, entry_point="sim.envs.gym_env:PlayroomGymEnv")

__all__ = ["GYM_ID", "PlayroomGymEnv", "PlayroomMovementEnv"]


def __getattr__(name: str) -> Any:
    if name == "PlayroomMovementEnv":
        from sim.envs import dm_env_movement

        return dm_env_movement.PlayroomMovementEnv
    if name == "PlayroomGymEnv":
        from sim.envs import gym_env

        return gym_env.PlayroomGymEnv
    raise AttributeError(f"module 'sim.envs' has no attribute {name!r}")
