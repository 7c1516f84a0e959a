"""A step between two conditions split into both tested in one world and their own worlds
against it, tested over agents paired by seed, with the split, the tests and the stars the
contact ladder's page uses."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from experiments.analysis import step_split
from experiments.analysis.world_steps import MEASURES, main, step_rows
from experiments.report import ladder


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
    assert means["whole step (each in its own world)"] == pytest.approx(0.0745, **near)
    both = "both tested in the {} world (B in it - A in it)"
    own = "own worlds against the {} world ((B own - B in it) - (A own - A in it))"
    assert means[both.format("kinematic")] == pytest.approx(0.05, **near)
    assert means[both.format("physical")] == pytest.approx(0.08, **near)
    # A's own world is the kinematic one: there the second part is B's own world against it.
    assert means[own.format("kinematic")] == pytest.approx(0.0245, **near)
    assert means[own.format("physical")] == pytest.approx(0.0245 - 0.03, **near)
    for world in ("kinematic", "physical"):
        total = means[both.format(world)] + means[own.format(world)]
        assert total == pytest.approx(means["whole step (each in its own world)"], abs=1e-12)
    assert (rows["n"] == 10).all() and (rows["p"] < 1e-3).all()


def test_a_paired_test_sees_a_shift_that_seed_noise_hides_from_an_unpaired_one():
    table = _table(6)
    rows = pd.DataFrame(step_rows(table, "A", "B"))
    both = rows[rows["part"].str.startswith("both tested in the kinematic")].iloc[0]
    assert both["p"] < 1e-6 and both["low"] < both["mean"] < both["high"]
    assert both["mean"] == pytest.approx(0.05, abs=0.003)
    assert both["p_rank"] == pytest.approx(2 / 2**6)  # 6 pairs of one sign: exact


def test_equal_agents_are_no_test_not_p_1_and_not_counted_in_holm():
    """An all-zero difference has no p (NaN), as on the ladder's page, so that it does not
    count in Holm's m: before, world_steps gave it p = 1.0 and counted it."""
    same = pd.DataFrame(step_rows(_table(6), "A", "A"))
    assert same["mean"].eq(0).all() and same["p"].isna().all() and same["p_rank"].isna().all()
    rows = pd.DataFrame(step_rows(_table(6), "A", "B") + step_rows(_table(6), "A", "A"))
    (adjusted,) = step_split.with_holm(rows)
    assert adjusted.loc[rows["p"].isna(), "p_holm"].isna().all()
    made = rows["p"].notna().sum()
    smallest = adjusted.loc[rows["p"].idxmin(), "p_holm"]
    assert smallest == pytest.approx(min(1.0, made * rows["p"].min()))


def test_world_steps_and_the_ladder_split_a_step_alike():
    """One definition: the ladder's split of a step and world_steps' give the same numbers."""
    table = _table(8)
    rows = pd.DataFrame(step_rows(table, "A", "B", measures=["competence_all"]))
    values = table.rename(columns={"condition": "rung"}).melt(
        id_vars=["rung", "seed", "tested"], value_vars=["competence_all"], var_name="key"
    )[ladder.VALUE_COLUMNS]
    splits = ladder.split_tests(values, ["A", "B"], []).query("key == 'competence_all'")
    for case in splits.to_dict("records"):
        text = step_split.PART_TEXT[case["part"]].format(world=case["world"])
        mine = rows[rows["part"] == text].iloc[0]
        for column in ("mean", "low", "high", "p", "p_rank", "n"):
            assert mine[column] == pytest.approx(case[column], nan_ok=True), (text, column)


def test_the_printed_table_stars_as_the_ladder_does_and_names_the_stars_that_differ(
    monkeypatch, capsys
):
    from experiments.analysis import world_steps

    monkeypatch.setattr(world_steps, "evaluations", lambda conditions, check=True: _table(6))
    main(["A=unused", "B=unused", "--steps", "A:B"])
    out = capsys.readouterr().out
    assert "t p | signed-rank p" in out
    # 6 seeds: every t survives Holm, no signed-rank p (2 / 2^6 at best) does.
    assert "Stars that differ between the t and the signed-rank test: 20" in out
    assert out.count("| 0.031 |") == 20
