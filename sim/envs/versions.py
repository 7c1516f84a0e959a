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
