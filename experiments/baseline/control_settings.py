"""The positive control's settings, every number in one place: which goals and seeds, how many
movements, how often and on which held-out goals the learner is tested, and the learner's
hyperparameters, each with why, beside stable-baselines3's defaults (read from the library).

The control asks whether a deep RL learner learns the goal environments at all where the task
is plainly learnable: the hand brought to a point, and the stick's handle carried to one, with
the arm alone and one movement a goal (sim/envs, goal ids v1, their defaults), a sparse reward.
docs/rl-baseline.md ("Positive control") has the results."""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from typing import Any

from sim.grasping.names import DEFAULT_GRASP, GRASPS

# The goals of the control: the two the arm reaches by itself in one movement, with no toy and
# no caregiver (sim/envs/goals.py: the study's models 1 and 2).
CONTROL_GOALS = ("hand", "stick")
SEEDS = 3
MOVEMENTS = 20_000  # per run: the movements the race gives each learner (docs/rl-baseline.md)
EVAL_EVERY = 2_000  # movements between two tests of the learner
EVAL_GOALS = 200  # held-out goals per test
# The held-out goals: the desired goal the environment draws at `reset(seed=s)` for the seeds
# FIRST_HELD_OUT_SEED, +1, ... (never one met at rest: goal ids v1), the same for every run,
# learner and test. Training episodes draw their rooms and goals from the run's own stream.
FIRST_HELD_OUT_SEED = 1_000_000
# Goals of the same kind for checking the settings (docs/rl-baseline.md, "The settings"), never
# the held-out ones.
FIRST_VALIDATION_SEED = 2_000_000
HELD_OUT, VALIDATION = "held-out", "validation"
FIRST_TEST_SEED = {HELD_OUT: FIRST_HELD_OUT_SEED, VALIDATION: FIRST_VALIDATION_SEED}
# The learner's settings: the control's (HYPERPARAMETERS), or stable-baselines3's defaults alone
# (the race's first learner, docs/rl-baseline.md).
CONTROL, DEFAULTS = "control", "defaults"
SETTINGS_CHOICES = (CONTROL, DEFAULTS)
# Random arm commands tried per held-out goal, for the chance level.
RANDOM_COMMANDS_PER_GOAL = 5
# torch's CPU threads: the networks are small; one thread keeps a run's arithmetic in one order.
TORCH_THREADS = 1
# The success on held-out goals a goal's learner should reach within MOVEMENTS (the
# target set for the hand: 90% within 20000 movements), drawn on the figure.
TARGETS = {"hand": 0.9}
LEARNER = "sac-her"  # the learner's name in the curves' table; "sac-her-defaults" with DEFAULTS
NEAREST = "nearest-outcome"
RANDOM = "random-commands"

# SAC's and HER's settings, each with why. The RL Zoo's tuned settings for FetchReach
# (rl-baselines3-zoo, hyperparams/sac.yml: a sparse-reward reaching task with HER, the nearest
# of its tasks to this one) where they apply; stable-baselines3's defaults elsewhere.
HYPERPARAMETERS: dict[str, tuple[Any, str]] = {
    "learning_rate": (1e-3, "the RL Zoo's FetchReach (the default is 3e-4)"),
    "buffer_size": (1_000_000, "every movement kept (the Zoo's and the default)"),
    "learning_starts": (1_000, "the Zoo's FetchReach: 1000 random movements before learning"),
    "batch_size": (256, "the Zoo's and the default"),
    "tau": (0.005, "the default (the Zoo's FetchReach keeps it)"),
    "gamma": (
        0.95,
        "the Zoo's FetchReach; without effect here, where every episode ends after its one "
        "movement (terminated: nothing is bootstrapped)",
    ),
    "train_freq": (1, "one gradient step a movement (the default)"),
    "gradient_steps": (1, "the default"),
    "ent_coef": ("auto", "entropy tuned to its target (the Zoo's and the default)"),
    "net_arch": ([64, 64], "the Zoo's FetchReach (the default is 256 x 256)"),
    "n_sampled_goal": (4, "HER: 4 relabelled goals a movement (the Zoo's and the default)"),
    "goal_selection_strategy": (
        "future",
        "HER's default; with one-movement episodes the future goal is the movement's own outcome",
    ),
}
# What each of HYPERPARAMETERS is in stable-baselines3 (the rest are SAC's own arguments).
HER_KEYS = ("n_sampled_goal", "goal_selection_strategy")
POLICY_KEYS = ("net_arch",)


class ControlError(Exception):
    """A control run that cannot run as asked; the message (one line) says why."""


def check_counts(settings: Any, lows: dict[str, int], error: type[Exception]) -> None:
    """`error` (one line) unless each field of `settings` named in `lows` is an integer (not a
    bool) at least its low; shared by the control's and the race's settings."""
    for name, low in lows.items():
        value = getattr(settings, name)
        if isinstance(value, bool) or not isinstance(value, int) or value < low:
            raise error(f"{name} must be an integer >= {low}, got {value!r}")


@dataclass(frozen=True)
class ControlSettings:
    """One control run: `movements` movements of SAC + HER (`settings`: the control's, or
    stable-baselines3's defaults) on `goal`'s environment from `seed`, tested on `eval_goals`
    goals (`test_goals`: the held-out ones, or the validation ones) every `eval_every`
    movements and before the first."""

    goal: str
    seed: int = 0
    movements: int = MOVEMENTS
    eval_every: int = EVAL_EVERY
    eval_goals: int = EVAL_GOALS
    grasp: str = DEFAULT_GRASP
    settings: str = CONTROL
    test_goals: str = HELD_OUT

    def __post_init__(self) -> None:
        for name, choices in (
            ("goal", CONTROL_GOALS),
            ("grasp", GRASPS),
            ("settings", SETTINGS_CHOICES),
            ("test_goals", tuple(FIRST_TEST_SEED)),
        ):
            if getattr(self, name) not in choices:
                raise ControlError(
                    f"unknown {name} {getattr(self, name)!r}: one of {', '.join(choices)}"
                )
        lows = {"seed": 0, "movements": 1, "eval_every": 1, "eval_goals": 1}
        check_counts(self, lows, ControlError)
        if self.movements % self.eval_every:
            raise ControlError(
                f"movements ({self.movements}) must be a multiple of eval_every "
                f"({self.eval_every}), so that the last test is at the end"
            )

    @property
    def name(self) -> str:
        """The run's name among others: its files' stem."""
        return f"{self.goal}-seed{self.seed:04d}"

    @property
    def learner(self) -> str:
        """The learner's name in the curves' table."""
        return LEARNER if self.settings == CONTROL else f"{LEARNER}-{DEFAULTS}"

    def test_seeds(self) -> range:
        """The reset seeds of the goals it is tested on."""
        first = FIRST_TEST_SEED[self.test_goals]
        return range(first, first + self.eval_goals)

    def checkpoints(self) -> list[int]:
        """The movements after which the learner is tested: 0, eval_every, ..., movements."""
        return list(range(0, self.movements + 1, self.eval_every))

    def record(self) -> dict:
        return dataclasses.asdict(self)


def learner_values() -> dict[str, Any]:
    """The hyperparameters' values alone."""
    return {name: value for name, (value, _) in HYPERPARAMETERS.items()}


def sac_arguments(settings: str = CONTROL) -> dict[str, Any]:
    """stable-baselines3's SAC keyword arguments of HYPERPARAMETERS (HerReplayBuffer's as
    `replay_buffer_kwargs`, the networks as `policy_kwargs`); none for DEFAULTS."""
    if settings == DEFAULTS:
        return {}
    values = learner_values()
    own = {k: v for k, v in values.items() if k not in HER_KEYS + POLICY_KEYS}
    return {
        **own,
        "replay_buffer_kwargs": {k: values[k] for k in HER_KEYS},
        "policy_kwargs": {k: values[k] for k in POLICY_KEYS},
    }


def library_defaults() -> dict[str, Any]:
    """stable-baselines3's own defaults of each hyperparameter, read from its signatures (the
    `rl` extra): what docs/rl-baseline.md reports beside the control's."""
    import inspect

    from gymnasium import spaces
    from stable_baselines3 import SAC, HerReplayBuffer
    from stable_baselines3.sac.policies import SACPolicy

    def defaults(function: Any) -> dict[str, Any]:
        return {
            name: p.default
            for name, p in inspect.signature(function).parameters.items()
            if p.default is not inspect.Parameter.empty
        }

    sac, her = defaults(SAC.__init__), defaults(HerReplayBuffer.__init__)
    out: dict[str, Any] = {}
    for name in HYPERPARAMETERS:
        if name in HER_KEYS:
            out[name] = her[name]
        elif name == "net_arch":  # None in the signature: what a policy built with it has
            box = spaces.Box(-1.0, 1.0, (1,))
            out[name] = list(SACPolicy(box, box, lambda _: 0.0).net_arch)
        else:
            out[name] = sac[name]
    return {k: v if isinstance(v, int | float | str | list) else str(v) for k, v in out.items()}
