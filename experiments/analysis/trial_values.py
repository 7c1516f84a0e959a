"""One value per trial of everything a comparison tests (the agent is the unit).

Each function takes a batch's tables (`BatchResults`, any number of groups) and returns one row
per trial of `results.trials`: its trial, group and seed, then one column per part of the
measure (`VALUE` for a measure of one part; "hand", "tool", "vocal" for strategy shares...).
A trial that has nothing to measure there (no test in a region, no tool use, a column its
evaluation did not record) holds NaN, never 0: the tests leave it out and say how many trials
they used.
"""

from __future__ import annotations

import math

import numpy as np
import pandas as pd

from experiments.analysis.results import BatchResults
from experiments.analysis.stats import STRATEGIES, TOOL_MIN_MOTION
from experiments.analysis.strategies import MOVERS, trial_shares

VALUE = "value"
KEYS = ["trial", "group", "seed"]
# The actors of a ring's tests and the columns of what moved the goal toy and the error left.
ACTORS = {"agent": ("goal_moved_by", "error"), "random": ("random_goal_moved_by", "random_error")}


def per_trial(results: BatchResults, values: pd.DataFrame | pd.Series) -> pd.DataFrame:
    """`values` (indexed by trial: a Series is one part, `VALUE`) on every trial of the batch,
    NaN for a trial it lacks."""
    frame = values.to_frame(VALUE) if isinstance(values, pd.Series) else values
    keys = results.trials[KEYS].reset_index(drop=True)
    joined = keys.join(frame, on="trial")
    return joined.astype({c: float for c in frame.columns})


def _empty(results: BatchResults, parts: tuple[str, ...] = (VALUE,)) -> pd.DataFrame:
    return per_trial(results, pd.DataFrame(columns=list(parts), dtype=float))


def trial_column(results: BatchResults, column: str) -> pd.DataFrame:
    """A number of the trials table (eval.json's, the logs' per-trial numbers)."""
    if column not in results.trials.columns:
        return _empty(results)
    return per_trial(results, results.trials.set_index("trial")[column].astype(float))


def strategy_shares(
    results: BatchResults, attribute: str, definition: str, low: float, high: float
) -> pd.DataFrame:
    """Each trial's share of its tests (`attribute`: "competence", the project's, or
    "study_tests") with the toy in [low, high) that used each strategy under `definition`."""
    shares = trial_shares(getattr(results, attribute), low, high, definition)
    if shares.empty:
        return _empty(results, STRATEGIES)
    return per_trial(results, shares.set_index("trial")[list(STRATEGIES)])


def words_within(results: BatchResults, threshold: float) -> pd.DataFrame:
    """Each trial's share of its words imitated within `threshold` (best distance below it)."""
    vocal = results.vocal
    if vocal.empty:
        return _empty(results)
    return per_trial(results, (vocal["best_distance"] < threshold).groupby(vocal["trial"]).mean())


# Which words a word measure takes (vocal table -> a mask of its rows).
WORDS = {
    "all words": lambda v: pd.Series(True, index=v.index),
    "toy names": lambda v: v["is_name"].astype(bool),
    "distractors": lambda v: ~v["is_name"].astype(bool),
}


def word_median(results: BatchResults, which: str) -> pd.DataFrame:
    """Each trial's median best distance over its words of `which` (WORDS); infinite where
    most were never approached (the tests leave such a trial out)."""
    vocal = results.vocal
    if vocal.empty:
        return _empty(results)
    chosen = vocal[WORDS[which](vocal)]
    return per_trial(results, chosen.groupby("trial")["best_distance"].median())


def names_gap(results: BatchResults) -> pd.DataFrame:
    """Each trial's median best distance of its distractors minus that of its names: positive
    where the names were imitated better. Not finite where a median is infinite."""
    names = word_median(results, "toy names")[VALUE].to_numpy()
    distractors = word_median(results, "distractors")[VALUE].to_numpy()
    with np.errstate(invalid="ignore"):
        gap = distractors - names
    keys = results.trials[KEYS].reset_index(drop=True)
    return keys.assign(**{VALUE: gap})


def catches_per_grasp(results: BatchResults) -> pd.DataFrame:
    """Each trial's toys caught with the stick per stick grasp (its two rates per 1000 arm
    movements divided); NaN for a trial that never grasped the stick."""
    trials = results.trials
    columns = ("toy_catches_per_1000_arm", "stick_grasps_per_1000_arm")
    if any(c not in trials.columns for c in columns):
        return _empty(results)
    catches, grasps = (trials.set_index("trial")[c].astype(float) for c in columns)
    return per_trial(results, catches / grasps.where(grasps > 0))


def only_pushed(results: BatchResults) -> pd.DataFrame:
    """Each trial's share of its tool tests (the project's tests, the study's rule: the stick
    moved) in which the hand never held the stick: it was only pushed."""
    tests = results.competence
    if tests.empty or "stick_grasped" not in tests.columns:
        return _empty(results)
    tools = tests[tests["strategy"] == "tool"]
    if tools["stick_grasped"].isna().any():
        return _empty(results)
    return per_trial(results, (~tools["stick_grasped"].astype(bool)).groupby(tools["trial"]).mean())


def _stick_motion(results: BatchResults) -> pd.DataFrame | None:
    """The study's tests with `stick_dx`, or None where a test lacks it (older evaluations)."""
    tests = results.study_tests
    if tests.empty or "stick_dx" not in tests.columns or tests["stick_dx"].isna().any():
        return None
    return tests


def small_tool_uses(results: BatchResults, min_motion: float = TOOL_MIN_MOTION) -> pd.DataFrame:
    """Each trial's share of its tool uses in the study's tests (its rule: the stick's x
    changed at all) in which the stick's x moved less than `min_motion` (m)."""
    tests = _stick_motion(results)
    if tests is None:
        return _empty(results)
    tools = tests[tests["strategy"] == "tool"]
    small = tools["stick_dx"].abs() < min_motion
    return per_trial(results, small.groupby(tools["trial"]).mean())


STUDY_RULE = "study's rule"


def at_least(min_motion: float) -> str:
    """The part of `study_tool_shares` that needs `min_motion` (m) of the stick's x."""
    return f"at least {1000 * min_motion:g} mm"


def study_tool_shares(results: BatchResults, min_motion: float = TOOL_MIN_MOTION) -> pd.DataFrame:
    """Each trial's tool share of its study tests: by the study's rule, and counting a tool
    use only when the stick's x moved at least `min_motion` (m; below it, the hand's)."""
    parts = (STUDY_RULE, at_least(min_motion))
    tests = _stick_motion(results)
    if tests is None:
        return _empty(results, parts)
    tool = tests["strategy"] == "tool"
    kept = tool & (tests["stick_dx"].abs() >= min_motion)
    shares = pd.DataFrame({parts[0]: tool, parts[1]: kept}).groupby(tests["trial"]).mean()
    return per_trial(results, shares)


def diverged_share(results: BatchResults) -> pd.DataFrame:
    """Each trial's share of its iterations whose physics diverged."""
    trials = results.trials.set_index("trial")
    if not {"diverged", "iterations"} <= set(trials.columns):
        return _empty(results)
    return per_trial(results, trials["diverged"] / trials["iterations"])


def seconds_per_iteration(results: BatchResults) -> pd.DataFrame:
    """Each trial's compute seconds per iteration (timing.json; NaN where not recorded)."""
    trials = results.trials.set_index("trial")
    if not {"seconds", "timed_iterations"} <= set(trials.columns):
        return _empty(results)
    return per_trial(results, trials["seconds"] / trials["timed_iterations"])


def ring_tests(results: BatchResults, ring: int) -> pd.DataFrame | None:
    """The project's tests of ring `ring`, or None where they do not record what moved the goal
    toy for both actors (evaluations before it)."""
    tests = results.competence
    needed = [column for column, _ in ACTORS.values()]
    if tests.empty or not set(needed) <= set(tests.columns):
        return None
    tests = tests[tests["ring"] == ring]
    return None if tests[needed].isna().any(axis=None) else tests


def ring_movers(results: BatchResults, ring: int, actor: str) -> pd.DataFrame:
    """Each trial's share of its ring-`ring` tests in which each mover (MOVERS) moved the goal
    toy, after the agent's chosen movement or a random command (`actor`) in the same scene."""
    tests = ring_tests(results, ring)
    if tests is None:
        return _empty(results, MOVERS)
    column = ACTORS[actor][0]
    shares = tests.groupby("trial")[column].value_counts(normalize=True).unstack(fill_value=0)
    return per_trial(results, shares.reindex(columns=list(MOVERS), fill_value=0.0))


def expectation_tests(results: BatchResults, ring: int) -> pd.DataFrame:
    """Ring `ring`'s arm tests of trained models (the agent chose the movement by its memory's
    nearest outcome): the rows the expectation gap is computed on."""
    tests = results.competence
    needed = {"ring", "strategy", "untrained", "arm_nn_distance", "error"}
    if tests.empty or not needed <= set(tests.columns):
        return tests.iloc[:0]
    chosen = (tests["ring"] == ring) & (tests["strategy"] != "vocal") & ~tests["untrained"]
    return tests[chosen.astype(bool)]


def expectation_gap(results: BatchResults, ring: int) -> pd.DataFrame:
    """Each trial's mean, over its ring-`ring` trained arm tests, of the error the movement
    left minus the error its memory led it to expect: how far outcomes fail to repeat."""
    tests = expectation_tests(results, ring)
    if tests.empty:
        return _empty(results)
    gap = tests["error"].astype(float) - tests["arm_nn_distance"].astype(float)
    return per_trial(results, gap.groupby(tests["trial"]).mean())


def mean_of(values: pd.DataFrame, part: str = VALUE) -> float:
    """The mean of a part's finite per-trial values; NaN without any."""
    column = values[part].to_numpy(dtype=float)
    column = column[np.isfinite(column)]
    return float(column.mean()) if len(column) else math.nan
