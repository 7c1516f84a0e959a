"""Every learning number of the study (docs/protocol.md §9), in one place.

The learner sees vectors only, so its units are those of the vectors: motor commands and
sensory goals live in [-1, 1]; positions in the sensory feedback are in the paper's length
units (metres in the MJCF model); sounds are in normalised log2-Hz (docs/protocol.md §4). The
10 sensorimotor models (which motor space, context and sensory dimensions each uses) are the
table `models.layout.MODELS`, with every size of the vectors.
"""

from __future__ import annotations

import dataclasses
import json
from dataclasses import dataclass
from typing import Any

from models import layout
from models.checks import INT64_MAX, check_bool, check_choice, check_int, check_number
from models.presets import PRESETS

BABBLING_MODES = ("random", "active")
IMITATION_DRAWS = ("distinct", "heard")
IMITATION_POOLS = ("recent", "all_heard")
BOOTSTRAPS = ("shuffled_learned", "coin_not_learned")
STORING_RULES = ("moved_from_start", "varies_about_mean")

# The bounds of the settings (the module docstring gives the units).
# The world takes commands in [-1, 1] (models/world.py): the motor bounds lie within.
MOTOR_LIMIT = 1
# Sensory values: positions on a table whose points lie within 1.84 m of the arm's base
# (models/playroom.xml, 2.6 m square) and sounds within [-1, 1]. Goals lie within twice the
# normalised range, and a change is at most the width of that, 4.
SENSORY_LIMIT = 2
# Histories the learner holds in memory and writes into every checkpoint: the progress window
# keeps 2 W float64 per model (160 MB for the 10 models at a million), the imitation memory 10
# float64 per sound (80 MB at a million); both far beyond a trial's attempts at the study's
# length. The bootstrap's order is a byte per command (10 MB at ten million of each).
HISTORY_MAX = 1_000_000
BOOTSTRAP_MAX = 10_000_000


@dataclass(frozen=True)
class LearnerConfig:
    # Motor commands live in [motor_low, motor_high] (their sizes: models/layout.py).
    motor_low: float = -1.0
    motor_high: float = 1.0
    # Bootstrap (docs/protocol.md §9): random commands before any goal babbling, in shuffled order.
    bootstrap_arm: int = 500  # commands
    bootstrap_voice: int = 500  # commands
    # Goal babbling: goals are drawn uniformly in [goal_low, goal_high]^10 of a sensory space.
    goal_low: float = -1.0
    goal_high: float = 1.0
    # Exploration noise added to the inverse model's command, in motor units. The paper says
    # 0.05; the study's public implementation used 0.1.
    exploration_sigma: float = 0.05
    # Model choice: "random" (the paper) or "active" (learning progress, public implementation).
    babbling: str = "random"
    active_random_share: float = 0.2  # share of uniformly random choices in "active" mode
    # Attempts per half-window of the progress measure (learner.interest). Not a number of the
    # protocol: the public implementation smoothed progress over about 1000 attempts instead.
    progress_window: int = 100  # attempts of one model
    # Imitation by model 10 (docs/protocol.md §9): share of its goals that are caregiver
    # sounds, drawn from the last `imitation_memory` sounds heard after arm movements.
    imitation_share: float = 0.5
    imitation_memory: int = 100  # sounds
    # "distinct": uniform over the distinct sounds of that window (the public implementation);
    # "heard": uniform over the window's entries, so frequent words are imitated more.
    imitation_draw: str = "distinct"
    # Storing rule: a sensory block "changed" when a value differs from its reference by more
    # than this (metres for positions, normalised log2-Hz for sounds). It absorbs the jitter of
    # resting objects in the physical backend; real movements are centimetres.
    change_tolerance: float = layout.MOVED_DISTANCE
    # How the study's code behaved where the paper is silent or says otherwise (docs/protocol.md
    # §11 D3-D8); the "study" preset (`learner_preset`) sets each to the code's behaviour.
    # "moved_from_start": a block changed when a sample left the object's start (or, for the
    # sound, silence); "varies_about_mean": when its 5 samples vary about their mean,
    # |x - mean x| + |y - mean y| > change_tolerance (the study's code).
    storing_rule: str = "moved_from_start"
    # The whole feedback clipped to [-1, 1] before learning, as the study's code did.
    clip_sensory: bool = False
    # "recent": imitation draws from the last `imitation_memory` sounds heard; "all_heard":
    # from every distinct caregiver word heard so far (the study's code).
    imitation_pool: str = "recent"
    # "shuffled_learned": exactly bootstrap_arm + bootstrap_voice random commands in a shuffled
    # order, learned from (the paper); "coin_not_learned": as many commands, each arm or voice
    # with probability 1/2, not learned from (the study's published runs).
    bootstrap: str = "shuffled_learned"
    # A model proposes random commands until it has stored this many different outcomes
    # (the study's code: 2).
    outcomes_to_infer: int = 1

    def __post_init__(self) -> None:
        """Every field checked when the config is built (ValueError, one line naming the
        field and what it allows): JSON types are not coerced, numbers must be finite."""
        c = "LearnerConfig."
        for name in ("progress_window", "imitation_memory"):
            check_int(c + name, getattr(self, name), 1, HISTORY_MAX)
        # A count of stored outcomes, compared with a model's rows: an int64 holds any.
        check_int(c + "outcomes_to_infer", self.outcomes_to_infer, 1, INT64_MAX)
        for name in ("bootstrap_arm", "bootstrap_voice"):
            check_int(c + name, getattr(self, name), 0, BOOTSTRAP_MAX)
        for low, high, limit in (
            ("motor_low", "motor_high", MOTOR_LIMIT),
            ("goal_low", "goal_high", SENSORY_LIMIT),
        ):
            check_number(c + low, getattr(self, low), f"[-{limit}, {limit}]")
            check_number(c + high, getattr(self, high), f"[-{limit}, {limit}]")
            if not getattr(self, low) < getattr(self, high):
                raise ValueError(
                    f"{c}{low} must be below {c}{high}, got {getattr(self, low)!r} >= "
                    f"{getattr(self, high)!r}"
                )
        # Noise beyond the width of the motor range is no longer exploration around a command.
        motor_range = self.motor_high - self.motor_low
        check_number(c + "exploration_sigma", self.exploration_sigma, f"[0, {motor_range!r}]")
        check_number(c + "change_tolerance", self.change_tolerance, f"[0, {2 * SENSORY_LIMIT}]")
        for name in ("active_random_share", "imitation_share"):
            check_number(c + name, getattr(self, name), "[0, 1]")
        for name, choices in (
            ("babbling", BABBLING_MODES),
            ("imitation_draw", IMITATION_DRAWS),
            ("imitation_pool", IMITATION_POOLS),
            ("bootstrap", BOOTSTRAPS),
            ("storing_rule", STORING_RULES),
        ):
            check_choice(c + name, getattr(self, name), choices)
        check_bool(c + "clip_sensory", self.clip_sensory)

    @property
    def n_bootstrap(self) -> int:
        return self.bootstrap_arm + self.bootstrap_voice

    def to_dict(self) -> dict[str, Any]:
        return dataclasses.asdict(self)

    @classmethod
    def from_dict(cls, values: dict[str, Any]) -> LearnerConfig:
        """Build from `to_dict()` output; unknown keys raise ValueError naming them."""
        known = {f.name for f in dataclasses.fields(cls)}
        unknown = sorted(set(values) - known)
        if unknown:
            raise ValueError(f"unknown LearnerConfig fields: {', '.join(unknown)}")
        return cls(**values)

    def to_json(self) -> str:
        return json.dumps(self.to_dict(), sort_keys=True)


def learner_preset(preset: str, **overrides: Any) -> LearnerConfig:
    """The learner of a preset: "study" behaves as the study's code did (docs/protocol.md
    §11 D3-D8: sigma 0.1, the published bootstrap, two outcomes before inferring, the storing
    rule on the samples' spread, clipped feedback, every heard word imitated); "project" keeps
    this project's earlier choices. `overrides` change single fields."""
    if preset not in PRESETS:
        raise ValueError(f"unknown preset {preset!r}: one of {PRESETS}")
    study = {
        "exploration_sigma": 0.1,
        "bootstrap": "coin_not_learned",
        "outcomes_to_infer": 2,
        "storing_rule": "varies_about_mean",
        "clip_sensory": True,
        "imitation_pool": "all_heard",
    }
    return LearnerConfig(**{**(study if preset == "study" else {}), **overrides})
