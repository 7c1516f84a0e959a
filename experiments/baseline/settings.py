"""What one baseline run is (`BaselineSettings`), every number of the baseline in one place, and
the trial whose world it shares: a baseline of grasp G and seed S learns in the world of
`playroom run --grasp G --seed S` (the same preset, voice and overrides), and is tested in that
trial's room, so that the two are compared on identical tests."""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np

from models.layout import TOYS
from models.presets import DEFAULT_PRESET
from models.tracts import DEFAULT_TRACT
from sim.grasping.names import DEFAULT_GRASP

if TYPE_CHECKING:
    from experiments.run.settings import TrialSettings

# The learner's name where a trial's summary names its babbling mode (eval.json's "babbling",
# which the analysis groups trials by): SAC with hindsight experience replay.
LEARNER = "sac-her"
# The algorithm and its replay buffer, stable-baselines3's classes, every other setting theirs.
ALGORITHM = "SAC"
REPLAY_BUFFER = "HerReplayBuffer"
POLICY = "MultiInputPolicy"
# The toy-goal environments as the race of docs/rl-baseline.md trained on them (their v0): both
# motor spaces behind the switch `a[0]` (as the policy actor reads the test's commands,
# experiments/measure/policy_actor.py) and episodes of 3 movements. v1 of the goal ids defaults to
# the arm alone and one movement (sim/envs/goal_env.py); it also never draws a goal already met.
MOTOR = "both"
EPISODE_MOVEMENTS = 3
# torch's CPU threads per run: the networks are small (256 x 256), so that runs side by side
# on every core (`--config`) go faster than one run on many threads; 1 also keeps a run's
# arithmetic in one order.
TORCH_THREADS = 1
# Placements per ring of the project's measure: the study's 100, as `playroom eval`'s default.
EVAL_PLACEMENTS = 100
# The largest number of movements a run may be asked for (a typo's guard: 10^9 movements would
# take years on the physical backend).
MAX_STEPS = 100_000_000


class BaselineError(Exception):
    """A baseline that cannot run as asked; the message (one line) says why."""


@dataclass(frozen=True)
class BaselineSettings:
    """One run: `steps` movements in all (one step of a goal environment is one movement, as
    one Model Babbling iteration is), split over the three toys' policies (`toy_steps`)."""

    steps: int
    grasp: str = DEFAULT_GRASP
    seed: int = 0
    preset: str = DEFAULT_PRESET
    voice: str = DEFAULT_TRACT
    overrides: dict = field(default_factory=dict)
    eval_placements: int = EVAL_PLACEMENTS
    torch_threads: int = TORCH_THREADS

    def __post_init__(self) -> None:
        for name, low, high in (
            ("steps", len(TOYS), MAX_STEPS),
            ("eval_placements", 1, None),
            ("torch_threads", 1, None),
        ):
            value = getattr(self, name)
            if isinstance(value, bool) or not isinstance(value, int) or value < low:
                raise BaselineError(f"{name} must be an integer >= {low}, got {value!r}")
            if high is not None and value > high:
                raise BaselineError(f"{name} must be at most {high}, got {value!r}")
        # Here, not at the module's top: the command line's parser reads this module's numbers
        # and must load no simulator (experiments/cli/main.py).
        from experiments.trial_dir.errors import TrialError

        try:
            self.trial()  # grasp, seed, preset, voice and overrides, as `playroom run` checks
        except TrialError as exc:
            raise BaselineError(str(exc)) from None

    def trial(self) -> TrialSettings:
        """The Model Babbling trial of the same world, seed and number of movements."""
        from experiments.run.settings import TrialSettings

        return TrialSettings(
            grasp=self.grasp,
            iterations=self.steps,
            seed=self.seed,
            checkpoint_every=self.steps,
            preset=self.preset,
            voice=self.voice,
            overrides=self.overrides,
        )

    def toy_steps(self) -> dict[int, int]:
        """Movements per toy's policy: an equal share each, the remainder to the first toys."""
        share, extra = divmod(self.steps, len(TOYS))
        return {t: share + (t <= extra) for t in range(1, len(TOYS) + 1)}

    def toy_seed(self, toy: int) -> int:
        """SAC's seed for toy `toy`'s policy (its networks, its exploration and its episodes'
        rooms): one stream per toy from the run's seed, so that the three policies do not
        explore with the same draws."""
        return int(np.random.SeedSequence([self.seed, toy]).generate_state(1)[0])

    def record(self) -> dict:
        """What baseline.json records of the settings; two runs of equal records are the same."""
        return dataclasses.asdict(self)


def trial_config(settings: BaselineSettings) -> dict:
    """The trial's config.json (experiments/run/trial_config.py `full_config`): the world, voice and
    learner settings the baseline's room is built from. BaselineError for settings that make
    none (a DIVA voice whose data is not installed)."""
    from experiments.run.trial_config import full_config
    from experiments.trial_dir.errors import TrialError

    try:
        return full_config(settings.trial())
    except TrialError as exc:
        raise BaselineError(str(exc)) from None


def summary_config(settings: BaselineSettings) -> dict:
    """A config of a trial's form for eval.json's summary (evaluation.summarise_trial): the
    learner in place of the babbling mode, the movements in place of the iterations."""
    return {
        "trial": {
            "grasp": settings.grasp,
            "seed": settings.seed,
            "babbling": LEARNER,
            "iterations": settings.steps,
        }
    }


def run_name(settings: BaselineSettings) -> str:
    """A run's directory name among others, as a batch names its trials."""
    return f"{settings.grasp}-{LEARNER}-seed{settings.seed:04d}"
