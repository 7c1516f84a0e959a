"""The goals of the goal-conditioned environments (sim/envs/goal_env.py), each one of the study's
own goal spaces (docs/protocol.md §8): what the agent achieved after a movement, read from the
study's sensory feedback; which goals are drawn, from the study's own placements and words; and
within what distance a goal counts as reached, the study's own distances.

Achieved goals:
- a position goal ("hand", "stick", "toy1"-"toy3") is where the block's object is at the
  movement's last sample (control step 50; `Feedback.s`, docs/protocol.md §4): the end point of
  the study's model 1 (hand), 2 (stick: the handle, as the study senses it) or 3-5 (a toy);
- the word goal ("word") is the agent's own sound, the 10 features of model 10 (5 F1 then 5 F2
  samples); after an arm movement the agent said nothing, and its sound is silence, zeros (the
  project's sensor reading when nobody speaks), not the caregiver's word that the feedback's
  sound block then holds.

Everything here is computed in float64 on whatever is given: the environments pass it their
float32 goals, so that a step's reward and `compute_reward` on the same goals agree exactly.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from models.layout import BLOCK_DIM, N_SAMPLES, TOYS, TRACKED_OBJECTS, block_slice
from sim.config import WorldConfig
from sim.envs.world import SOUND_BOUND
from sim.playroom import Playroom
from sim.vocal.config import VoiceConfig

SOUND = "sound"
WORD = "word"
# The rings `info["ring"]` names (`ring_of`): a point the hand reaches, or one only a held
# stick's end reaches.
NEAR, FAR = "near", "far"
# Draws of a desired goal before `draw_unmet` gives up: a goal space where this many draws are
# all met at rest is a world the environment cannot set a task in (in the study's worlds fewer
# than 5% of draws are met: the stick's handle, 4.3%).
MAX_DRAWS = 1000


@dataclass(frozen=True)
class Goal:
    """One goal space: the sensory block it reads (models.layout.SENSORY_BLOCKS)."""

    name: str
    block: str

    @property
    def is_position(self) -> bool:
        return self.block != SOUND

    @property
    def dim(self) -> int:
        """A position's x, y at the last sample; a sound's 10 features."""
        return 2 if self.is_position else BLOCK_DIM


# Each the goal space of the study's models (docs/protocol.md §8): hand, model 1 (arm -> hand);
# stick, model 2 (arm -> stick, the handle); a toy, models 3-5 (arm) and 7-9 (voice, through the
# caregiver); word, model 10 (voice -> sound).
GOALS: dict[str, Goal] = {
    name: Goal(name, block)
    for name, block in (
        ("hand", "hand"),
        ("stick", "stick"),
        *((toy, toy) for toy in TOYS),
        (WORD, SOUND),
    )
}


def checked_goal(name: object) -> Goal:
    """The goal of that name, or ValueError in one line naming the goals."""
    if not isinstance(name, str) or name not in GOALS:
        raise ValueError(f"unknown goal {name!r}: one of {', '.join(GOALS)}")
    return GOALS[name]


def tolerance(goal: Goal, config: WorldConfig, voice: VoiceConfig) -> float:
    """The one distance within which a goal is reached (Euclidean, strictly less), each the
    study's own: a position within `grasp_distance` (0.1 m: the distance within which the
    study's hand takes an object, §5, so an object brought that near is within the hand's grasp
    of the point); a sound within `recognition_distance` (0.4 in the 10 features: the distance
    within which the caregiver recognises a word, §6)."""
    return config.grasp_distance if goal.is_position else voice.recognition_distance


def bound(goal: Goal, room: Playroom) -> float:
    """How far a goal's numbers go: positions within the table's half-size (m), as the
    observation's; sounds within SOUND_BOUND."""
    if goal.is_position:
        return float(room.physics.named.model.geom_size["table", 0])
    return SOUND_BOUND


def achieved_after(goal: Goal, s: np.ndarray, motor_space: str) -> np.ndarray:
    """What a movement achieved (see the module's docstring) from its feedback s (60,)."""
    block = s[block_slice(goal.block)]
    if goal.is_position:
        return np.array([block[N_SAMPLES - 1], block[BLOCK_DIM - 1]])
    return block.copy() if motor_space == "voice" else np.zeros(BLOCK_DIM)


def achieved_at_rest(goal: Goal, room: Playroom) -> np.ndarray:
    """What is achieved before any movement: where the object lies; for the voice, silence."""
    if goal.is_position:
        return room.physics.tracked_positions()[TRACKED_OBJECTS.index(goal.block)].copy()
    return np.zeros(BLOCK_DIM)


def reach_rings(goal: Goal, config: WorldConfig) -> tuple[tuple[float, float], ...]:
    """Where position goals are drawn, as (inner, outer) radii from the arm's base (m):
    - hand and stick handle: the arm's reach, [0, sum of segment_lengths] (a held stick's
      handle is at the hand);
    - a toy: the study's placement rings (`toy_rings`) that the hand or a held stick's end
      reaches, outer radius within the arm's length plus the stick's (rings 1 and 2 of the
      study: [0, 0.5] and [0.5, 0.75] m; ring 3 is reached only with the caregiver's help)."""
    arm = sum(config.segment_lengths)
    if goal.name in ("hand", "stick"):
        return ((0.0, arm),)
    # (A tolerance for float sums: 0.25 + 0.15 + 0.10 + 0.25 against a ring's 0.75.)
    return tuple(r for r in config.toy_rings if r[1] <= arm + config.stick_length + 1e-9)


def draw_desired(
    goal: Goal, room: Playroom, rng: np.random.Generator
) -> tuple[np.ndarray, str | None]:
    """A desired goal and, for a word, its name. Positions follow the study's placement rule
    (docs/protocol.md §1) over `reach_rings`: a ring with equal chance, a radius uniform in it,
    an angle uniform in [0, 2 pi). Words: one of the caregiver's words (names and distractors
    alike) with equal chance, its perfect features in the room's vocal tract (§6)."""
    if not goal.is_position:
        words = room.vocal_tract.config.words
        word = words[int(rng.integers(len(words)))]
        return room.vocal_tract.word_features(word), word
    rings = reach_rings(goal, room.config)
    low, high = rings[int(rng.integers(len(rings)))]
    radius = rng.uniform(low, high)
    angle = rng.uniform(0.0, 2.0 * np.pi)
    return radius * np.array([np.cos(angle), np.sin(angle)]), None


def draw_unmet(
    goal: Goal, room: Playroom, rng: np.random.Generator, tolerance: float
) -> tuple[np.ndarray, str | None]:
    """A desired goal (float32) not already met where things lie (`achieved_at_rest`), and for
    a word its name: `draw_desired` again until the goal lies at `tolerance` or more from what is
    achieved at rest (distances of the float32 goals, as the rewards are computed). So its
    distribution is the study's placement rule with the goals already met cut out. RuntimeError
    after MAX_DRAWS draws all met."""
    at_rest = achieved_at_rest(goal, room).astype(np.float32)
    for _ in range(MAX_DRAWS):
        desired, word = draw_desired(goal, room, rng)
        desired = desired.astype(np.float32)
        if distance(at_rest, desired) >= tolerance:
            return desired, word
    raise RuntimeError(
        f"{MAX_DRAWS} desired {goal.name} goals drawn were all met at rest: this world leaves "
        "no goal to reach"
    )


def ring_of(goal: Goal, desired: np.ndarray, config: WorldConfig) -> str | None:
    """Where a position goal lies: NEAR within the arm's reach (`arm_length`, 0.5 m from its
    base: the study's ring 1, the hand's), FAR beyond it (ring 2: only a held stick's end
    reaches it); None for a sound."""
    if not goal.is_position:
        return None
    reach = config.arm_length
    return NEAR if float(np.linalg.norm(np.asarray(desired, dtype=np.float64))) <= reach else FAR


def distance(achieved: np.ndarray, desired: np.ndarray) -> np.ndarray:
    """Euclidean distances over the last axis, of single goals (d,) or batches (n, d)."""
    a = np.asarray(achieved, dtype=np.float64)
    d = np.asarray(desired, dtype=np.float64)
    if a.shape[-1:] != d.shape[-1:]:
        raise ValueError(
            f"achieved and desired goals must share their last axis, got {a.shape} and {d.shape}"
        )
    return np.sqrt(np.sum((a - d) ** 2, axis=-1))
