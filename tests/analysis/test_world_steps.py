"""A step between two conditions split into what the agents learned and what the test world
does, tested over agents paired by seed."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from experiments.analysis.world_steps import MEASURES, holm, paired, step_rows


def _table(seeds: int = 10) -> pd.DataFrame:
    """A: learned 0.10 (+ seed noise) tested anywhere. B: learned 0.05 more; its own world adds
    0.02 to every agent of it; A's own world is the kinematic one."""
    rng = np.random.default_rng(0)
    rows = []
    for seed in range(seeds):
        base = 0.10 + 0.01 * rng.standard_normal()
        gain = 0.05 + 0.002 * rng.standard_normal()  # what B's agent learned more, per seed
        for condition, learned, own_bonus in (("A", base, 0.0), ("B", base + gain, 0.02)):
            for tested in ("own", "kinematic", "physical"):
                value = learned + (own_bonus * (1 + 0.05 * seed) if tested == "own" else 0.0)
                if condition == "A" and tested == "physical":
                    value = learned - 0.03  # another world is harder for A's agents
                rows.append(
                    {"condition": condition, "seed": seed, "tested": tested}
                    | dict.fromkeys(MEASURES, value)
                )
    return pd.DataFrame(rows)


def test_the_parts_of_a_step_are_measured_on_the_same_agents():
    rows = pd.DataFrame(step_rows(_table(), "A", "B")).query("measure == 'competence_all'")
    means = dict(zip(rows["part"], rows["mean"], strict=True))
    near = {"abs": 0.003}
    assert means["whole step (own worlds)"] == pytest.approx(0.0745, **near)
    assert means["learned (both tested in the kinematic world)"] == pytest.approx(0.05, **near)
    assert means["learned (both tested in the physical world)"] == pytest.approx(0.08, **near)
    assert means["test world (B in its own against in kinematic)"] == pytest.approx(0.0245, **near)
    assert (rows["n"] == 10).all() and (rows["p"] < 1e-6).all()


def test_a_paired_test_sees_a_shift_that_seed_noise_hides_from_an_unpaired_one():
    table = _table(6)
    result = paired(table, ("A", "kinematic"), ("B", "kinematic"), "competence_all")
    assert result["p"] < 1e-6 and result["low"] < result["mean"] < result["high"]
    assert result["mean"] == pytest.approx(0.05, abs=0.003)
    same = paired(table, ("A", "kinematic"), ("A", "kinematic"), "competence_all")
    assert same["mean"] == 0 and same["p"] == 1.0


def test_holm_adjusts_as_computed_by_hand():
    p = pd.Series([0.01, 0.04, 0.03, np.nan], index=list("abcd"))
    adjusted = holm(p)
    # Sorted 0.01, 0.03, 0.04: 3 x 0.01, max(0.03, 2 x 0.03), max(0.06, 1 x 0.04).
    assert adjusted["a"] == pytest.approx(0.03)
    assert adjusted["c"] == pytest.approx(0.06)
    assert adjusted["b"] == pytest.approx(0.06)
    assert np.isnan(adjusted["d"])
