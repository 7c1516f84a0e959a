"""The race's settings, every number in one place: Model Babbling against two deep RL learners
(SAC + HER with stable-baselines3's defaults, and with the positive control's settings) and
random arm commands (the chance level), one
goal-conditioned policy for the three toys (PlayroomToysGoal-v1: the toy part of the goal, the
arm alone, one movement a goal), each given the same movements, all tested on the same held-out
toy goals at the same budgets. Model Babbling's trials are the batch config's
(experiments/batches/rl-baseline/comparison.json: grasps, seeds, movements, babbling, preset).
docs/rl-race.md says what it measures and what it costs."""

from __future__ import annotations

import dataclasses
import os
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

from experiments.baseline.control_settings import CONTROL, DEFAULTS, ControlError, check_counts

if TYPE_CHECKING:  # the command line's help reads this module: it loads no batch or world
    from experiments.run.settings import TrialSettings

RACE_CONFIG = Path("experiments") / "batches" / "rl-baseline" / "comparison.json"
MODEL_BABBLING = "model-babbling"
SAC_DEFAULTS = "sac-her-defaults"  # SAC + HER, stable-baselines3's defaults
SAC_CONTROL = "sac-her"  # SAC + HER, the positive control's settings (control_settings.py)
# The chance level on the same goals: uniform random arm commands (no learning: the same share
# at every budget), RANDOM_COMMANDS_PER_GOAL of them a goal.
RANDOM_COMMANDS = "random-commands"
LEARNERS = (MODEL_BABBLING, SAC_DEFAULTS, SAC_CONTROL, RANDOM_COMMANDS)
# Each deep RL learner's settings in control_settings.py's names.
SAC_SETTINGS = {SAC_DEFAULTS: DEFAULTS, SAC_CONTROL: CONTROL}
EVAL_EVERY = 2_000  # movements between two tests of every learner
EVAL_GOALS = 300  # held-out goals a test: about 100 a toy, half near, half far
# The held-out goals: the goal PlayroomToysGoal-v1 draws at `reset(seed=s)` for s =
# FIRST_HELD_OUT_SEED, +1, ... (toy and point, never met at rest), the same for every learner,
# run and budget; the control's own held-out seeds, in another environment.
FIRST_HELD_OUT_SEED = 1_000_000
# The paired test of a claim: two-sided Wilcoxon signed-rank over seeds, at this level.
ALPHA = 0.05


class RaceError(ControlError):
    """A race that cannot run as asked; the message (one line) says why."""


@dataclass(frozen=True)
class RaceRun:
    """One learner on one grasp backend and seed: `trial`'s movements (a batch config's trial:
    its grasp, seed, world, babbling, iterations), tested every `eval_every` movements on
    `eval_goals` held-out goals."""

    learner: str
    trial: TrialSettings
    eval_every: int = EVAL_EVERY
    eval_goals: int = EVAL_GOALS

    def __post_init__(self) -> None:
        if self.learner not in LEARNERS:
            raise RaceError(f"unknown learner {self.learner!r}: one of {', '.join(LEARNERS)}")
        check_counts(self, {"eval_every": 1, "eval_goals": 1}, RaceError)
        if self.movements % self.eval_every:
            raise RaceError(
                f"the trials' iterations ({self.movements}) must be a multiple of the tests' "
                f"period ({self.eval_every}), so that the last test is at the end"
            )

    @property
    def movements(self) -> int:
        return self.trial.iterations

    @property
    def name(self) -> str:
        """The run's files' stem."""
        return f"{self.learner}-{self.trial.grasp}-seed{self.trial.seed:04d}"

    def budgets(self) -> list[int]:
        """The movements after which the learner is tested: eval_every, ..., movements."""
        return list(range(self.eval_every, self.movements + 1, self.eval_every))

    def trial_at(self, budget: int) -> TrialSettings:
        """Model Babbling's trial run to `budget` iterations (a trial extended to the next
        budget equals one asked for it from the start: experiments/run/trial.py), with a
        checkpoint at every budget."""
        return dataclasses.replace(
            self.trial, iterations=budget, checkpoint_every=min(self.eval_every, budget)
        )

    def test_seeds(self) -> range:
        return range(FIRST_HELD_OUT_SEED, FIRST_HELD_OUT_SEED + self.eval_goals)

    def shared(self) -> dict:
        """What every run of a race directory shares: all but the learner, grasp and seed."""
        trial = dataclasses.asdict(self.trial)
        for own in ("grasp", "seed", "checkpoint_every"):
            trial.pop(own)
        return {"trial": trial, "eval_every": self.eval_every, "eval_goals": self.eval_goals}


def race_runs(
    config_file: str | os.PathLike,
    learners: Sequence[str] = LEARNERS,
    seeds: int | None = None,
    iterations: int | None = None,
    grasps: Sequence[str] | None = None,
    eval_every: int = EVAL_EVERY,
    eval_goals: int = EVAL_GOALS,
) -> list[RaceRun]:
    """Each learner's run for every trial of a batch config (the first `seeds` of its seeds,
    `iterations` for its own, `grasps` of its grasps where given: a smaller race of the same
    form); RaceError (one line) for a config the toys' goal environment cannot match."""
    from experiments.batches.spec import BatchError, load_spec
    from sim.config import WorldConfig

    try:
        spec = load_spec(config_file=config_file)
    except BatchError as exc:
        raise RaceError(str(exc)) from None
    if len(spec.babbling) != 1 or spec.overrides or spec.eval_worlds:
        raise RaceError(
            f"{config_file}: the race takes one babbling mode, no overrides and no eval_worlds "
            "(the goal environment has the study's world as it is)"
        )
    if spec.stick_return != WorldConfig.stick_return:
        raise RaceError(f"{config_file}: the goal environment has the default stick_return")
    unknown = sorted(set(grasps or ()) - set(spec.grasps))
    if unknown:
        raise RaceError(f"grasps {unknown} are not the config's: one of {', '.join(spec.grasps)}")
    trials = [t for _, t in spec.trials() if grasps is None or t.grasp in grasps]
    if seeds is not None:
        trials = [t for t in trials if t.seed in spec.seeds[:seeds]]
    if iterations is not None:
        trials = [dataclasses.replace(t, iterations=iterations) for t in trials]
    return [RaceRun(learner, t, eval_every, eval_goals) for learner in learners for t in trials]
