"""One registry of the measures the pages test: each a `Measure` entry, read by the
comparison's table of differences (experiments/report/differences.py), the ablation table
(experiments/report/ablations.py) and summary.json (experiments/report/summary.py). A new row
of those is one entry here.

An entry says what the measure is (name, label, kind: how its values read), how one value per
trial is computed from a batch's tables (experiments/analysis/trial_values.py), and how it is
tested: `DIFFERENCE` (the two groups' per-trial values, paired over seeds where the seeds pair:
experiments/analysis/trial_tests.py), `GAP` (each group's per-trial values against 0, then the
interaction: the groups' per-trial values compared) or `NONE` (said why). A value a backend
fixes by construction (`Fixed`: nothing is pushed where the backend pushes nothing) is shown,
not tested. A pooled test, which treats tests or words as independent, is only a second line
(experiments/analysis/pooled_tests.py).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from functools import partial

import pandas as pd

from experiments.analysis import pooled_tests, trial_values
from experiments.analysis.geometry import Geometry
from experiments.analysis.mechanisms import LABELS
from experiments.analysis.results import BatchResults
from experiments.analysis.stats import STRATEGIES, TOOL_MIN_MOTION, regions
from experiments.analysis.strategies import DEFINITIONS, MOVERS
from experiments.analysis.trial_rows import COMPETENCE_SCOPES
from experiments.analysis.trial_tests import PooledTest
from experiments.analysis.trial_values import VALUE
from experiments.report import measure_notes as notes

DIFFERENCE, GAP, NONE = "difference", "gap", "none"
# How a kind's values read on the pages (experiments/report/differences.py formats them).
KINDS = ("share", "rate", "ratio", "count", "distance", "iteration", "seconds")


@dataclass(frozen=True)
class Fixed:
    """A value that parts of a measure take by construction in a group whose trials declare
    it (`declared`, on the group's trials table: its backend's capabilities, backend.json).
    Such a part is shown, never tested: it is known, not sampled. Where a group that declares
    it holds any other value, the declaration does not hold and the part is tested."""

    value: float
    declared: Callable[[pd.DataFrame], bool]
    reason: str
    parts: tuple[str, ...] | None = None  # None: every part


@dataclass(frozen=True)
class Measure:
    """One measure of the pages (module docstring). `values`: a batch's tables -> one row per
    trial (trial, group, seed, one column per part). `tested`: the parts tested (default all).
    `pooled`: the second line's pooled tests of two sides. `note`: a side's counts behind its
    values, shown beside them. `missing`: what a side without any value reads."""

    name: str
    label: str
    kind: str
    values: Callable[[BatchResults], pd.DataFrame]
    parts: tuple[str, ...] = (VALUE,)
    test: str = DIFFERENCE
    tested: tuple[str, ...] | None = None
    untested: str = ""
    fixed: tuple[Fixed, ...] = ()
    pooled: Callable[[BatchResults, BatchResults], list[PooledTest]] | None = None
    note: Callable[[BatchResults], str] | None = None
    missing: str = "not recorded"
    in_ablations: bool = False
    short: str = ""

    def __post_init__(self) -> None:
        if self.kind not in KINDS or self.test not in (DIFFERENCE, GAP, NONE):
            raise ValueError(f"measure {self.name}: kind {self.kind!r}, test {self.test!r}")
        if self.test == NONE and not self.untested:
            raise ValueError(f"measure {self.name} is not tested: say why (untested)")

    @property
    def tested_parts(self) -> tuple[str, ...]:
        return () if self.test == NONE else (self.tested or self.parts)


def _declares(capability: str, value: bool) -> Callable[[pd.DataFrame], bool]:
    """Whether every trial of a group declares `capability` (backend.json) as `value`."""

    def check(trials: pd.DataFrame) -> bool:
        return capability in trials.columns and bool((trials[capability] == value).all())

    return check


NOTHING_PUSHED = "its backend pushes nothing (backend.json: pushes false)"
PUSHES_NOTHING = Fixed(0.0, _declares("pushes", False), f"{NOTHING_PUSHED}: 0 by construction")
# A backend that pushes nothing moves the stick only in the hand, which never leaves its reach.
STICK_KEPT = "and its hand keeps the stick within its reach"
NEVER_RETURNED = Fixed(0.0, _declares("pushes", False), f"{NOTHING_PUSHED} {STICK_KEPT}: 0")
ALWAYS_IN_REACH = Fixed(1.0, _declares("pushes", False), f"{NOTHING_PUSHED} {STICK_KEPT}: 100%")
NO_PHYSICS = Fixed(
    0.0,
    _declares("closed_form", True),
    "its movements are computed in closed form (backend.json): no physics to diverge",
)


def _competence() -> list[Measure]:
    return [
        Measure(
            f"competence_{scope}",
            "Normalised competence, "
            + ("all rings" if scope == "all" else scope.replace("ring", "ring ")),
            "share",
            partial(trial_values.trial_column, column=f"competence_{scope}"),
            in_ablations=scope == "all",
        )
        for scope in COMPETENCE_SCOPES
    ]


# The two sets of tests each trial holds, named as the pages name them.
TEST_SETS = {
    "project": ("competence", "project's tests"),
    "study": ("study_tests", "study's tests"),
}


def _strategies(geometry: Geometry) -> list[Measure]:
    out = []
    areas = regions(geometry.hand_limit, geometry.stick_limit)
    for key, (attribute, words) in TEST_SETS.items():
        for definition, meaning in DEFINITIONS.items():
            for region, (low, high) in areas.items():
                out.append(
                    Measure(
                        f"strategies_{key}_{definition}_{region.replace(' ', '_')}",
                        f"Strategies ({words}; {meaning}), {region}",
                        "share",
                        partial(
                            trial_values.strategy_shares,
                            attribute=attribute,
                            definition=definition,
                            low=low,
                            high=high,
                        ),
                        parts=STRATEGIES,
                        pooled=partial(
                            pooled_tests.strategies,
                            attribute=attribute,
                            definition=definition,
                            low=low,
                            high=high,
                        ),
                        note=partial(notes.tests_in, attribute=attribute, low=low, high=high),
                        missing="no tests here",
                    )
                )
    return out


def _vocal(threshold: float) -> list[Measure]:
    out = [
        Measure(
            "words_within",
            f"Words imitated within {threshold:g} (each trial's share of its words)",
            "share",
            partial(trial_values.words_within, threshold=threshold),
            pooled=partial(pooled_tests.words_within, threshold=threshold),
            note=notes.words,
            in_ablations=True,
        )
    ]
    for which in trial_values.WORDS:
        out.append(
            Measure(
                f"median_best_distance_{which.replace(' ', '_')}",
                f"Best word distance, {which} (each trial's median)",
                "distance",
                partial(trial_values.word_median, which=which),
                pooled=partial(pooled_tests.word_distances, which=which),
            )
        )
    out.append(
        Measure(
            "names_vs_distractors",
            "Names vs distractors: each trial's gap, median best distance of its distractors "
            "minus its names (positive: names imitated better)",
            "distance",
            trial_values.names_gap,
            test=GAP,
            pooled=lambda a, b: [pooled_tests.names_vs_distractors(s) for s in (a, b)],
            in_ablations=True,
            short="the names' gap (each trial's median, distractors minus names)",
        )
    )
    return out


# Per-trial stick numbers of the trials table (experiments/analysis/curves.py).
STICK = (
    (
        "stick_in_reach",
        "Iterations that began with the stick within reach",
        "share",
        ALWAYS_IN_REACH,
    ),
    ("stick_grasps_per_1000_arm", "Stick grasps per 1000 arm movements", "rate", None),
    ("toy_catches_per_1000_arm", "Toys caught with the stick per 1000 arm movements", "rate", None),
    ("stick_returns", "Stick returns by the experimenter per trial", "count", NEVER_RETURNED),
)


def _stick() -> list[Measure]:
    out = [
        Measure(
            column,
            label,
            kind,
            partial(trial_values.trial_column, column=column),
            fixed=(fixed,) if fixed else (),
        )
        for column, label, kind, fixed in STICK
    ]
    out.append(
        Measure(
            "toy_catches_per_stick_grasp",
            "Toys caught with the stick per stick grasp (each trial's two rates divided)",
            "ratio",
            trial_values.catches_per_grasp,
            missing="no stick grasp (or not recorded)",
        )
    )
    out.append(
        Measure(
            "tool_tests_only_pushed",
            "Tool tests (study's rule) in which the stick was only pushed, never held "
            "(each trial's share of its tool tests)",
            "share",
            trial_values.only_pushed,
            fixed=(PUSHES_NOTHING,),
            pooled=pooled_tests.tool_contacts,
            note=notes.held_or_pushed,
            missing="no tool test (or not recorded)",
        )
    )
    return out


def tool_rule_measures(min_motion: float = TOOL_MIN_MOTION) -> list[Measure]:
    minimum = f"{1000 * min_motion:g} mm"
    return [
        Measure(
            "study_tool_uses_below_min_motion",
            f"Study's tool uses that moved the stick's x less than {minimum} "
            "(each trial's share of its tool uses)",
            "share",
            partial(trial_values.small_tool_uses, min_motion=min_motion),
            pooled=partial(pooled_tests.small_tool_uses, min_motion=min_motion),
            note=partial(notes.small_tool_uses, min_motion=min_motion),
        ),
        Measure(
            "study_tool_share",
            f"Study's tests: tool share, its rule / with at least {minimum}",
            "share",
            partial(trial_values.study_tool_shares, min_motion=min_motion),
            parts=(trial_values.STUDY_RULE, trial_values.at_least(min_motion)),
            # The study's rule is tested region by region in the strategy rows above.
            tested=(trial_values.at_least(min_motion),),
            pooled=partial(pooled_tests.tool_share_min_motion, min_motion=min_motion),
            note=notes.study_tests,
        ),
    ]


def _cost() -> list[Measure]:
    return [
        Measure(
            "diverged",
            "Iterations whose physics diverged (each trial's share)",
            "share",
            trial_values.diverged_share,
            fixed=(NO_PHYSICS,),
            pooled=pooled_tests.diverged,
            note=notes.diverged,
        ),
        Measure(
            "seconds_per_iteration",
            "Cost per iteration (timing.json: trial seconds / iterations)",
            "seconds",
            trial_values.seconds_per_iteration,
            test=NONE,
            untested="a timing depends on the machine and its load, not only on the agents",
        ),
    ]


# Numbers of the logs shown as shares rather than counts.
LOG_SHARES = {k for k in LABELS if k.startswith("model_share_")} | {
    "name_recognised_after_toy_goal"
}
LOG_FIXED = {"toy_pushed": PUSHES_NOTHING, "stick_pushed": PUSHES_NOTHING}


def _mechanisms(ring: int = 1) -> list[Measure]:
    out = []
    for actor, who in (("agent", "the agent's chosen movement"), ("random", "a random command")):
        out.append(
            Measure(
                f"ring{ring}_goal_moved_by_{actor}",
                f"Ring {ring} tests: what moved the goal toy after {who} "
                "(each trial's share of its tests)",
                "share",
                partial(trial_values.ring_movers, ring=ring, actor=actor),
                parts=MOVERS,
                fixed=(Fixed(0.0, PUSHES_NOTHING.declared, PUSHES_NOTHING.reason, ("push",)),),
                pooled=partial(pooled_tests.ring_movers, ring=ring, actor=actor),
                note=partial(notes.errors_left, ring=ring, actor=actor),
            )
        )
    out.append(
        Measure(
            f"ring{ring}_expectation_gap",
            f"Ring {ring} arm tests: error left by the movement minus error expected from "
            "memory (each trial's mean)",
            "distance",
            partial(trial_values.expectation_gap, ring=ring),
            pooled=partial(pooled_tests.expectation_gaps, ring=ring),
            note=partial(notes.expected_and_left, ring=ring),
        )
    )
    for key, label in LABELS.items():
        kind = "share" if key in LOG_SHARES else "rate" if "per 1000" in label else "count"
        kind = "iteration" if key.startswith("first_") else kind
        fixed = LOG_FIXED.get(key)
        out.append(
            Measure(
                f"log_{key}",
                f"Logs: {label}",
                kind,
                partial(trial_values.trial_column, column=key),
                fixed=(fixed,) if fixed else (),
            )
        )
    return out


def registry(geometry: Geometry) -> tuple[Measure, ...]:
    """Every measure of the pages, in the order the comparison's table shows them; regions and
    the recognition distance from the trials' settings (`geometry`)."""
    measures = (
        *_competence(),
        *_strategies(geometry),
        *_vocal(geometry.threshold),
        *_stick(),
        *tool_rule_measures(),
        *_cost(),
        *_mechanisms(),
    )
    names = [m.name for m in measures]
    if len(set(names)) != len(names):  # summary.json keys them by name
        raise ValueError(f"two measures share a name: {sorted(names)}")
    return measures
