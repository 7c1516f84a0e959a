"""The study's world numbers (protocol.md), in one place, with their units.

Lengths are in the paper's units, which are metres in the MJCF model. Every number the world
uses that comes from the protocol lives here; the MJCF file holds only physical tuning.
"""

from __future__ import annotations

import math
from dataclasses import dataclass


@dataclass(frozen=True)
class WorldConfig:
    # Arm (protocol.md, "World").
    segment_lengths: tuple[float, float, float] = (0.25, 0.15, 0.10)  # m
    arm_rest_offset: float = math.pi / 2  # rad: at rest the arm points along +y
    # DMPs (protocol.md, "One iteration").
    n_steps: int = 50  # control steps per movement
    arm_bfs: int = 6  # basis functions per joint
    voice_bfs: int = 2  # basis functions per articulator
    dmp_weight_scale: float = 300.0  # scales the weights in [-1, 1]
    sample_steps: tuple[int, ...] = (1, 13, 25, 38, 50)  # 1-based steps where objects are sampled
    # Objects.
    stick_length: float = 0.25  # m
    stick_start_handle: tuple[float, float] = (-0.25, 0.0)  # m
    stick_start_angle: float = math.pi / 2  # rad: pointing along +y
    n_toys: int = 3
    toy_replace_period: int = 20  # iterations between toy placements
    toy_rings: tuple[tuple[float, float], ...] = ((0.0, 0.5), (0.5, 0.75), (0.75, 1.0))  # m
    caregiver_box: float = 1.0  # caregiver uniform in [-box, box]^2, m
    # Kinematic grasp rules (protocol.md, "Grasp rules of the study").
    grasp_distance: float = 0.1  # m, hand to handle or toy
    catch_distance: float = 0.1  # m, stick tip to toy
    # Caregiver bringing a toy: fraction of the remaining way per control step.
    caregiver_bring_rate: float = 0.01

    @property
    def sample_indices(self) -> tuple[int, ...]:
        """0-based indices into a 50-step trajectory of the 5 sample steps."""
        return tuple(s - 1 for s in self.sample_steps)


DEFAULT_WORLD = WorldConfig()

# Motor and sensory layout (protocol.md): these follow from the numbers above.
ARM_DIM = 3 * (DEFAULT_WORLD.arm_bfs + 1)  # 21
VOICE_DIM = 7 * (DEFAULT_WORLD.voice_bfs + 2)  # 28
CONTEXT_DIM = 2 * (2 + DEFAULT_WORLD.n_toys)  # 10: stick handle, toys, caregiver
SENSORY_DIM = 60  # hand, stick, toy1-3 (10D each), sound (10D)
SENSORY_BLOCKS: dict[str, slice] = {
    "hand": slice(0, 10),
    "stick": slice(10, 20),
    "toy1": slice(20, 30),
    "toy2": slice(30, 40),
    "toy3": slice(40, 50),
    "sound": slice(50, 60),
}
