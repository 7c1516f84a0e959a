"""The sections of `playroom bench`, by name, without what measures them: the command line
lists them in its help without loading a simulator (experiments/bench/sections.py measures)."""

from __future__ import annotations

SECTION_NAMES = ("trial", "learner", "world", "tracking", "voice", "render", "emulated", "long")
# Run only when named (minutes): `playroom bench` alone leaves them out.
ON_REQUEST = ("long",)
# What each section measures, for the command line's help.
SECTION_HELP = {
    "trial": "whole trials of both backends against 500 bare mj_step (fastest of 3 runs each, "
    "in turns); the replication's 80000-iteration trial alone and two at once (~1.5 min)",
    "learner": "the memory's query against brute force; the learner per iteration at "
    "10000-80000 rows a model; peak memory",
    "world": "an arm iteration of each backend against bare mj_step; how slowly the Python "
    "run after MuJoCo's steps comes back on this machine",
    "tracking": "how closely the physical arm follows its DMP targets",
    "voice": "the fitted formant map against the exact path; the vocal part of an iteration",
    "render": "offscreen rendering (needs OpenGL: MUJOCO_GL)",
    "emulated": "trial and learner again under the other CPU class's settings (a second process)",
    "long": "only when named: one trial of 10^6 iterations; cost per iteration and checkpoint "
    "bytes near 80000 and near its end, peak memory; each model's query on its memories, "
    "scanned whole and through the trees, and as they grew (~5 min)",
}
