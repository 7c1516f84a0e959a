"""What the race may claim (experiments/baseline/race_claims.py): a difference between Model
Babbling and a deep RL learner is stated only where Wilcoxon's signed-rank test over the seeds'
paired differences rejects equality; too few seeds, or differences of both signs, state none."""

from __future__ import annotations

import pandas as pd
import pytest

from experiments.baseline.race_claims import HIGHER, LOWER, NONE_SHOWN, claims, paired_p
from experiments.baseline.race_settings import MODEL_BABBLING, SAC_DEFAULTS


def _table(ours: list[float], theirs: list[float], ring: str = "near") -> pd.DataFrame:
    rows = [
        {
            "learner": learner,
            "grasp": "kinematic",
            "seed": seed,
            "steps": 2000,
            "ring": ring,
            "goals": 100,
            "success": success,
        }  # fmt: skip
        for learner, values in ((MODEL_BABBLING, ours), (SAC_DEFAULTS, theirs))
        for seed, success in enumerate(values)
    ]
    return pd.DataFrame(rows)


EIGHT_HIGHER = (
    [0.3, 0.4, 0.35, 0.5, 0.45, 0.3, 0.6, 0.4],
    [0.1, 0.2, 0.05, 0.1, 0.3, 0.1, 0.2, 0.2],
)


@pytest.mark.parametrize(
    ("ours", "theirs", "claim"),
    [
        (*EIGHT_HIGHER, HIGHER),  # every one of 8 seeds higher: p = 2/2^8
        (EIGHT_HIGHER[1], EIGHT_HIGHER[0], LOWER),
        (EIGHT_HIGHER[0][:3], EIGHT_HIGHER[1][:3], NONE_SHOWN),  # 3 seeds: p >= 0.25
        (
            [0.2, 0.1, 0.3, 0.2, 0.1, 0.3, 0.2, 0.1],
            [0.1, 0.2, 0.2, 0.3, 0.2, 0.2, 0.1, 0.2],
            NONE_SHOWN,
        ),
        ([0.0] * 8, [0.0] * 8, NONE_SHOWN),  # nothing reached by either: no difference
    ],
)
def test_a_difference_is_claimed_only_where_the_paired_test_rejects(ours, theirs, claim):
    (row,) = claims(_table(ours, theirs)).to_dict("records")
    assert row["claim"] == claim
    assert row["seeds"] == len(ours) and row["learner"] == SAC_DEFAULTS
    assert row["mean_difference"] == pytest.approx(
        sum(ours) / len(ours) - sum(theirs) / len(theirs)
    )


def test_only_seeds_both_learners_ran_are_paired():
    table = _table(*EIGHT_HIGHER)
    table = table[~((table["learner"] == SAC_DEFAULTS) & (table["seed"] >= 4))]
    (row,) = claims(table).to_dict("records")
    assert row["seeds"] == 4 and row["claim"] == NONE_SHOWN  # 4 pairs: p >= 0.125


def test_the_p_value_is_wilcoxons_exact_one():
    assert paired_p([0.1] * 8) == pytest.approx(2 / 2**8)
    assert paired_p([0.0, 0.0]) == 1.0
