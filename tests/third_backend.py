"""Third grasp backends, for the tests that adding one is its module and one registry line:
the study's distance rules with the hand reaching twice as far (`LongReachGrasp`), and the
physical backend with another grasp rule, a part the playroom builds (`TouchlessGrasp`)."""

from __future__ import annotations

import dataclasses

from sim.grasping.contact_rule import ContactRule
from sim.grasping.kinematic import KinematicGrasp
from sim.grasping.physical import PhysicalGrasp


class LongReachGrasp(KinematicGrasp):
    name = "long_reach"

    def __init__(self, config, edits, carrying, rule=None) -> None:
        reach = 2 * config.grasp_distance
        super().__init__(dataclasses.replace(config, grasp_distance=reach), edits, carrying, rule)


class TakesNothing(ContactRule):
    """A contact rule under which no touch takes anything."""

    def take(self, physics, holds, step):
        return holds, []


class TouchlessGrasp(PhysicalGrasp):
    """The physical backend with another part: its dynamics and the caregiver's carrying as
    they are, its grasp rule one that takes nothing."""

    name = "touchless"
    rule_class = TakesNothing
