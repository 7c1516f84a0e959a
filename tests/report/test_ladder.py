"""The contact ladder's tests over trials (`playroom ladder`): steps paired by seed that add up
to the whole difference, each step of competence split into what the agents learned and what
the test worlds do, Holm over every test of the page, and the page's files."""

import json
import math

import numpy as np
import pandas as pd
import pytest

from experiments.analysis.trial_tests import holm
from experiments.cli.main import main
from experiments.report import ladder

SEEDS = range(6)
KEY = "competence_ring1"


def _values(levels: dict[str, dict[str, float]], drop: tuple[str, int] | None = None):
    """Rows of every rung tested in each world given (`levels`: rung -> tested -> base), one
    value per seed (the base plus a seed's own noise, the same in every rung so that pairing
    removes it)."""
    rng = np.random.default_rng(1)
    noise = {s: float(rng.normal(0, 0.05)) for s in SEEDS}
    rows = []
    for rung, worlds in levels.items():
        for tested, base in worlds.items():
            for s in SEEDS:
                if drop != (rung, s):
                    value = base + noise[s] + float(rng.normal(0, 0.002))
                    rows.append((rung, tested, s, KEY, value))
    return pd.DataFrame(rows, columns=ladder.VALUE_COLUMNS)


def _headline():
    from experiments.report.measures import Measure

    measure = Measure(KEY, "ring 1", "share", lambda r: r)
    return [ladder.Headline(KEY, measure, "value", "ring 1")]


LEVELS = {
    "A": {"own": 0.10, "kinematic": 0.10, "physical": 0.05},
    "B": {"own": 0.12, "kinematic": 0.13, "physical": 0.06},
    "C": {"own": -0.02, "kinematic": 0.04, "physical": -0.02},
}


def test_the_steps_add_up_to_the_whole_difference_paired_by_seed():
    values = _values(LEVELS)
    steps = ladder.step_tests(values, ["A", "B", "C"], [], _headline())
    mine = steps.set_index("kind")
    assert list(steps["kind"]) == ["step", "step", "whole"]
    assert mine.loc["whole", "mean"] == pytest.approx(-0.12, abs=0.01)
    (total,) = ladder.steps_sum(steps).to_dict("records")
    assert total["whole_minus_sum"] == pytest.approx(0.0, abs=1e-12)
    assert total["within"]
    # Paired by seed: the seeds' shared noise (sd 0.05) leaves the step's interval narrow.
    first = steps.iloc[0]
    assert first["high"] - first["low"] < 0.01 and first["p"] < 1e-3 and first["n"] == 6


def test_a_rung_missing_a_seed_leaves_it_out_of_every_step_and_says_the_whole_on_all():
    values = _values(LEVELS, drop=("B", 3))
    steps = ladder.step_tests(values, ["A", "B", "C"], [], _headline())
    by_kind = steps.set_index("kind")
    assert set(steps.loc[steps["kind"] != "whole_all", "n"]) == {5}
    assert by_kind.loc["whole_all", "n"] == 6
    assert ladder.steps_sum(steps)["whole_minus_sum"].abs().max() < 1e-12


def test_a_rung_beside_the_ladder_is_set_against_the_last_rung():
    levels = {**LEVELS, "D": {"own": 0.03}}
    steps = ladder.step_tests(_values(levels), ["A", "B", "C"], ["D"], _headline())
    beside = steps[steps["kind"] == "beside"].iloc[0]
    assert (beside["from"], beside["to"]) == ("C", "D")
    assert beside["mean"] == pytest.approx(0.05, abs=0.01)


def test_each_step_splits_into_learned_and_test_worlds_that_add_up_seed_by_seed():
    values = _values(LEVELS)
    splits = ladder.split_tests(values, ["A", "B", "C"], [])
    steps = ladder.step_tests(values, ["A", "B", "C"], [], _headline())
    for (a, b, world), rows in splits.groupby(["from", "to", "world"]):
        parts = rows.set_index("part")["mean"]
        step = steps[(steps["from"] == a) & (steps["to"] == b)]["mean"].iloc[0]
        assert parts["learned"] + parts["worlds"] == pytest.approx(step, abs=1e-12), (a, b, world)
    # B -> C tested in the kinematic world: the agents learned -0.09, the worlds do -0.05.
    bc = splits[(splits["from"] == "B") & (splits["to"] == "C") & (splits["world"] == "kinematic")]
    learned = bc.set_index("part").loc["learned", "mean"]
    assert learned == pytest.approx(-0.09, abs=0.01)


def test_a_rung_not_tested_in_a_world_leaves_that_world_out_of_its_steps():
    levels = {**LEVELS, "B": {"own": 0.12, "kinematic": 0.13}}
    splits = ladder.split_tests(_values(levels), ["A", "B", "C"], [])
    assert set(splits["world"]) == {"kinematic", "physical"}
    assert not ((splits["world"] == "physical") & (splits["to"] == "B")).any()
    assert not ((splits["world"] == "physical") & (splits["from"] == "B")).any()


def test_holm_runs_over_every_test_of_both_tables():
    values = _values(LEVELS)
    steps = ladder.step_tests(values, ["A", "B", "C"], [], _headline())
    splits = ladder.split_tests(values, ["A", "B", "C"], [])
    steps, splits = ladder.with_holm(steps, splits)
    ps = [*steps["p"], *splits["p"]]
    expected = holm(ps)
    np.testing.assert_allclose([*steps["p_holm"], *splits["p_holm"]], expected)


@pytest.mark.parametrize("text", ["A", "=dir", "A="])
def test_a_rung_is_named_with_its_directory(text):
    with pytest.raises(ValueError, match="NAME=DIR"):
        ladder.parse_rung(text)


def test_a_rung_names_an_optional_group():
    rung = ladder.parse_rung("study=runs/comparison-diva:kinematic")
    assert (rung.name, str(rung.batch_dir), rung.group) == (
        "study",
        "runs/comparison-diva",
        "kinematic",
    )


def test_the_page_writes_every_trials_values_and_every_test(batches, tmp_path, capsys):
    out = tmp_path / "ladder"
    rungs = [f"a={batches['kinematic']}", f"b={batches['kinematic']}:kinematic"]
    assert main(["ladder", *rungs, "--out", str(out)]) == 0
    page = (out / "ladder.md").read_text()
    assert "## Each rung's step" in page and "No test here pools" in page
    record = json.loads((out / "ladder.json").read_text())
    seeds = {v["seed"] for v in record["values"] if v["rung"] == "a"}
    assert seeds == {0, 1}
    # The same agents on both rungs: every step is 0 and untested, never p = 0 or 1.
    assert all(s["p"] is None for s in record["steps"] if s["mean"] == 0)
    assert (out / "ladder.png").stat().st_size > 0
    tests = pd.read_csv(out / "ladder.csv")
    assert {"key", "kind", "from", "to", "mean", "low", "high", "p", "n", "p_holm"} <= set(tests)


def test_a_group_the_batch_does_not_hold_is_refused_in_one_line(batches, tmp_path, capsys):
    rungs = [f"a={batches['kinematic']}:physical", f"b={batches['kinematic']}"]
    assert main(["ladder", *rungs, "--out", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err.strip()
    assert err.count("\n") == 0 and "holds no group 'physical'" in err
    assert not (tmp_path / "out").exists()


def test_catches_per_grasp_is_each_trials_ratio_and_missing_without_a_grasp(batches):
    from experiments.analysis import trial_values
    from experiments.analysis.results import collect

    results = collect(batches["kinematic"])
    ratio = trial_values.catches_per_grasp(results).set_index("trial")["value"]
    trials = results.trials.set_index("trial")
    grasps = trials["stick_grasps_per_1000_arm"].astype(float)
    catches = trials["toy_catches_per_1000_arm"].astype(float)
    for trial in trials.index:
        if grasps[trial] > 0:
            assert ratio[trial] == pytest.approx(catches[trial] / grasps[trial])
        else:
            assert math.isnan(ratio[trial])


def test_the_whole_on_every_seed_is_shown_only_where_the_ends_share_more_seeds():
    values = _values(LEVELS, drop=("C", 3))  # the last rung lacks a seed: nothing more to say
    steps = ladder.step_tests(values, ["A", "B", "C"], [], _headline())
    assert "whole_all" not in set(steps["kind"])


def test_the_rungs_means_are_over_the_seeds_the_steps_pair(batches, tmp_path):
    """The first rung's mean plus the steps is the last rung's: both on the seeds every rung
    holds (the kinematic batch holds seeds 0 and 1, the physical one seed 0 only)."""
    rungs = [f"a={batches['kinematic']}", f"b={batches['physical']}"]
    assert main(["ladder", *rungs, "--out", str(tmp_path / "out")]) == 0
    record = json.loads((tmp_path / "out" / "ladder.json").read_text())
    own = [lv for lv in record["levels"] if lv["tested"] == "own"]
    assert {lv["n"] for lv in own if lv["rung"] == "a"} == {1}
    (step,) = [s for s in record["steps"] if s["key"] == "competence_all" and s["kind"] == "step"]
    mean = {lv["rung"]: lv["mean"] for lv in own if lv["key"] == "competence_all"}
    assert mean["a"] + step["mean"] == pytest.approx(mean["b"])
