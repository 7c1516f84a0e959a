"""A third grasp backend, for the test that adding one is its module and one registry line:
the study's distance rules with the hand reaching twice as far."""

from __future__ import annotations

import dataclasses

from sim.grasping.kinematic import KinematicGrasp


class LongReachGrasp(KinematicGrasp):
    name = "long_reach"

    def __init__(self, config, edits) -> None:
        reach = 2 * config.grasp_distance
        super().__init__(dataclasses.replace(config, grasp_distance=reach), edits)
