"""The contact ladder's tests over trials (`playroom ladder`): steps paired by seed, a paired t
and a signed-rank p for each, each step of competence split into both rungs' agents tested in
one world and their own worlds against it, one family declared before the values with Holm over
it, a completeness check, and the page's files."""

import dataclasses
import io
import json
import math
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from trial_batches import batch
from trial_recompute import ladder_case

from experiments.analysis import step_split
from experiments.analysis.trial_tests import holm
from experiments.cli.main import main
from experiments.report import ladder, ladder_data
from experiments.report.trial_data import read_trial_data

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


def test_each_step_is_paired_by_seed_with_a_t_and_a_signed_rank_p():
    values = _values(LEVELS)
    steps = ladder.step_tests(values, ["A", "B", "C"], [], _headline())
    mine = steps.set_index("kind")
    assert list(steps["kind"]) == ["step", "step", "whole"]
    assert mine.loc["whole", "mean"] == pytest.approx(-0.12, abs=0.01)
    # Paired by seed: the seeds' shared noise (sd 0.05) leaves the step's interval narrow.
    first = steps.iloc[0]
    assert first["high"] - first["low"] < 0.01 and first["p"] < 1e-3 and first["n"] == 6
    # 6 pairs all of one sign: the exact signed-rank p is 2 / 2^6.
    assert first["p_rank"] == pytest.approx(2 / 2**6)


def test_a_rung_missing_a_seed_leaves_it_out_of_every_step_and_says_the_whole_on_all():
    values = _values(LEVELS, drop=("B", 3))
    steps = ladder.step_tests(values, ["A", "B", "C"], [], _headline())
    by_kind = steps.set_index("kind")
    assert set(steps.loc[steps["kind"] != "whole_all", "n"]) == {5}
    assert by_kind.loc["whole_all", "n"] == 6


def test_the_completeness_check_names_what_each_rung_lacks_and_no_sum_stands_in_for_it():
    """The steps' sum equals the whole for any rungs on the same seeds (a telescoping sum): the
    page checks instead that every rung holds every seed in every world."""
    values = _values(LEVELS, drop=("B", 3))
    values = values[~((values["rung"] == "C") & (values["tested"] == "physical"))]
    check = ladder.completeness(values, ["A", "B", "C"]).set_index("rung")
    assert check.loc["A", "complete"] and not check.loc["B", "complete"]
    assert check.loc["B", "missing_own"] == [3] and check.loc["B", "missing_kinematic"] == [3]
    assert check.loc["C", "missing_physical"] == list(SEEDS)
    assert not check.loc["C", "complete"]
    assert not hasattr(ladder, "steps_sum")


def test_a_rung_beside_the_ladder_is_set_against_the_last_rung():
    levels = {**LEVELS, "D": {"own": 0.03}}
    steps = ladder.step_tests(_values(levels), ["A", "B", "C"], ["D"], _headline())
    beside = steps[steps["kind"] == "beside"].iloc[0]
    assert (beside["from"], beside["to"]) == ("C", "D")
    assert beside["mean"] == pytest.approx(0.05, abs=0.01)


def test_each_step_splits_into_both_tested_in_a_world_and_own_worlds_against_it():
    # A rung lacking a seed, and one beside the ladder: each split adds up to the step it
    # splits, on that step's seeds (a rung beside: every seed it and the last rung hold).
    levels = {**LEVELS, "D": {"own": 0.03, "kinematic": 0.05, "physical": 0.0}}
    values = _values(levels, drop=("B", 3))
    splits = ladder.split_tests(values, ["A", "B", "C"], ["D"]).query("key == @KEY")
    steps = ladder.step_tests(values, ["A", "B", "C"], ["D"], _headline())
    assert set(splits["part"]) == {"both_in_world", "own_against_world"}
    assert set(splits.loc[splits["to"] == "D", "n"]) == {6}
    for (a, b, world), rows in splits.groupby(["from", "to", "world"]):
        parts = rows.set_index("part")["mean"]
        step = steps[(steps["from"] == a) & (steps["to"] == b)]["mean"].iloc[0]
        total = parts["both_in_world"] + parts["own_against_world"]
        assert total == pytest.approx(step, abs=1e-12), (a, b, world)
    # B -> C tested in the kinematic world: both there -0.09; their own worlds against it
    # (C own - C there) - (B own - B there) = -0.06 - (-0.01) = -0.05.
    bc = splits[(splits["from"] == "B") & (splits["to"] == "C") & (splits["world"] == "kinematic")]
    parts = bc.set_index("part")["mean"]
    assert parts["both_in_world"] == pytest.approx(-0.09, abs=0.01)
    assert parts["own_against_world"] == pytest.approx(-0.05, abs=0.01)


def test_a_world_a_rung_was_not_tested_in_is_in_the_family_without_a_test():
    levels = {**LEVELS, "B": {"own": 0.12, "kinematic": 0.13}}
    splits = ladder.split_tests(_values(levels), ["A", "B", "C"], []).query("key == @KEY")
    untested = (splits["world"] == "physical") & ((splits["to"] == "B") | (splits["from"] == "B"))
    assert untested.any() and (splits.loc[untested, "n"] == 0).all()
    assert splits.loc[untested, ["p", "p_rank"]].isna().all().all()
    assert splits.loc[~untested, "p"].notna().all()


def test_the_family_is_fixed_by_the_rungs_and_measures_alone():
    """Two ladders of the same rungs and measures, with values as unlike as can be, have the
    same family: what is tested does not depend on what the values say."""
    other = _values({r: {w: -v for w, v in ws.items()} for r, ws in LEVELS.items()})
    tables = []
    for values in (_values(LEVELS), other):
        steps = ladder.step_tests(values, ["A", "B", "C"], ["C"], _headline())
        splits = ladder.split_tests(values, ["A", "B", "C"], ["C"])
        tables.append(pd.concat([steps, splits])[["key", "kind", "from", "to"]])
    pd.testing.assert_frame_equal(tables[0], tables[1])
    declared = ladder.family(["A", "B", "C"], ["C"], _headline(), ends_hold_more=False)
    assert len(declared) == len(tables[0])


def test_holm_runs_over_every_test_of_both_tables_for_each_kind_of_p():
    values = _values(LEVELS)
    steps = ladder.step_tests(values, ["A", "B", "C"], [], _headline())
    splits = ladder.split_tests(values, ["A", "B", "C"], [])
    steps, splits = step_split.with_holm(steps, splits)
    for column, adjusted in (("p", "p_holm"), ("p_rank", "p_rank_holm")):
        expected = holm([*steps[column], *splits[column]])
        np.testing.assert_allclose([*steps[adjusted], *splits[adjusted]], expected)


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
    assert "whole (first to last)" not in page and "(whole)" not in page  # two rungs: one step
    record = json.loads((out / "ladder.json").read_text())
    seeds = {v["seed"] for v in record["values"] if v["rung"] == "a"}
    assert seeds == {0, 1}
    # The same agents on both rungs: every step is 0 and untested, never p = 0 or 1.
    assert all(s["p"] is None for s in record["steps"] if s["mean"] == 0)
    assert (out / "ladder.png").stat().st_size > 0
    tests = pd.read_csv(out / "ladder.csv")
    assert {"key", "kind", "from", "to", "mean", "low", "high", "p", "n", "p_holm"} <= set(tests)
    # Every trial in its own world, with who computed it (the trials' provenance.json).
    trials = read_trial_data(out / "ladder-trials.csv").query("tested == 'own'")
    assert sorted(zip(trials["rung"], trials["seed"], strict=True)) == [
        ("a", 0),
        ("a", 1),
        ("b", 0),
        ("b", 1),
    ]
    assert trials["computed_commit"].str.fullmatch(r"[0-9a-f]{7}(\+dirty)?").all()
    assert trials["computed_on"].str.contains("from iteration 0").all()
    assert trials["evaluated_on"].ne("not recorded").all()
    assert set(record["measures"]) <= set(trials.columns)


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


# What each backend records of itself (backend.json) in the study preset's world.
BACKENDS = {
    "kinematic": {"reach": 0.6, "solid": False, "pushes": False, "closed_form": True},
    "physical": {"reach": 0.546, "solid": True, "pushes": True, "closed_form": False},
}


def _config(grasp: str, **world) -> dict:
    """config.json's settings of a study-preset trial (the seed left out, as a group's)."""
    from sim.config import world_preset

    return {
        "trial": {"grasp": grasp, "preset": "study"},
        "world": dataclasses.asdict(world_preset("study", **world)),
    }


def _read(values: pd.DataFrame, configs: dict[str, dict]) -> ladder.LadderRead:
    """A ladder read from hand-made values: each rung's own results a hand-made batch with the
    rung's config (`configs`: rung -> _config) and its backend's record."""
    own = {}
    for rung, config in configs.items():
        seeds = values.loc[(values["rung"] == rung) & (values["tested"] == "own"), "seed"]
        results = batch(rung, sorted(set(seeds)))
        record = BACKENDS[config["trial"]["grasp"]]
        if config["trial"]["grasp"] == "physical" and not config["world"]["push_objects"]:
            record = {**record, "pushes": False}
        trials = results.trials.drop(columns=["pushes", "closed_form"]).assign(**record)
        own[rung] = dataclasses.replace(results, trials=trials, configs={rung: config})
    where = []
    for rung, tested in values[["rung", "tested"]].drop_duplicates().itertuples(index=False):
        seeds = set(values.loc[(values["rung"] == rung) & (values["tested"] == tested), "seed"])
        where.append(ladder_data.provenance(own[rung].with_seeds(seeds), rung, tested))
    return ladder.LadderRead(values, _headline(), own, pd.concat(where), [])


def test_the_page_gives_a_rank_p_beside_every_t_and_names_the_cells_whose_star_differs():
    """With 6 seeds the signed-rank p cannot go below 2 / 2^6 (no star under Holm), while the
    t stars the steps the seeds' shared noise does not hide: each such cell is named."""
    from experiments.report.ladder_page import ladder_files

    rungs = [ladder.Rung(r, Path(r)) for r in ("A", "B", "C")]
    read = _read(_values(LEVELS), {r: _config("kinematic") for r in ("A", "B", "C")})
    files = ladder_files(read, rungs, [], "playroom ladder A=A B=B C=C --out x")
    page = files["ladder.md"].decode()
    tests = pd.read_csv(io.BytesIO(files["ladder.csv"]))
    made = tests[tests["p"].notna()]
    assert made["p_rank"].notna().all() and len(made)
    tables = page.split("## The family of tests")[0]
    assert tables.count("; rank p = ") == tables.count(", p = ") == len(made)
    differ = made[(made["p_holm"] <= 0.05) != (made["p_rank_holm"] <= 0.05)]
    assert len(differ) > 0
    section = page.split("## Where the t and the signed-rank test disagree on a star")[1]
    assert section.count("starred by the t only") == len(differ)
    assert "A -> B (step)" in section
    assert f"One family of {len(tests)} tests" in page and "steps' sum" not in page
    assert "## Completeness" in page and "Complete: every rung holds every seed" in page


def test_a_rung_of_another_backend_lists_everything_it_changes_and_who_reads_it():
    """servo-arm -> contact-aligned: a setting the earlier rung never read is said so (it did
    not push or weld anything), a rule only one rung applies is listed although its value did
    not change, and what each rung's world does as its trials recorded it."""
    from experiments.report.ladder_page import ladder_files

    configs = {
        "servo-arm": _config("kinematic", catch_rule="held_stick", arm_dynamics="servo"),
        "contact-aligned": _config("physical", push_objects=False, held_pose="aligned"),
    }
    values = _values({"servo-arm": LEVELS["A"], "contact-aligned": LEVELS["B"]})
    rungs = [ladder.Rung(r, Path(r)) for r in configs]
    page = ladder_files(_read(values, configs), rungs, [], "cmd")["ladder.md"].decode()
    row = next(line for line in page.splitlines() if line.startswith("| contact-aligned |"))
    for said in (
        "trial.grasp: kinematic -> physical",
        "world.push_objects: True -> False (not read by the earlier rung's kinematic backend)",
        "world.held_pose: touch -> aligned (not read by the earlier rung's kinematic backend)",
        "world.arm_dynamics: servo -> set (not read by the later rung's physical backend)",
        "world.catch_distance: 0.1, read by the earlier rung's kinematic backend only",
        "world.stick_return_reach: 0.53, read by the later rung's physical backend only",
        "backend: the hand takes the stick's handle within (m) 0.600 -> 0.546",
        "backend: solid objects (placements clear of the stick and of each other; unheld "
        "objects block the hand and what it holds): no -> yes",
        "backend: movements computed in closed form (no dynamics): yes -> no",
    ):
        assert said in row, said
    assert "objects pushed" not in row  # neither rung pushes


def test_one_order_is_worded_as_each_rule_given_the_rules_before_it():
    from experiments.report.ladder_figure import waterfall
    from experiments.report.ladder_page import ladder_files

    read = _read(_values(LEVELS), {r: _config("kinematic") for r in ("A", "B", "C")})
    rungs = [ladder.Rung(r, Path(r)) for r in ("A", "B", "C")]
    page = ladder_files(read, rungs, [], "cmd")["ladder.md"].decode()
    assert "## Each rung's step, given the rules before it" in page
    steps = ladder.step_tests(read.values, ["A", "B", "C"], [], _headline())
    levels = ladder.levels(read.values)
    figure = waterfall(_headline(), steps, levels, ["A", "B", "C"])
    assert "given the rules before it" in figure.get_suptitle()


def test_every_number_of_the_page_is_computed_again_from_its_per_trial_data_alone():
    """ladder-trials.csv, the data published beside the page, holds all a reader needs: each
    test's mean, interval, t and signed-rank p, and each rung's mean, computed from it with
    scipy alone, are the page's (a rung lacking a seed and a rung beside the ladder included)."""
    from experiments.report.ladder_page import ladder_files

    levels = {**LEVELS, "D": {"own": 0.03, "kinematic": 0.05, "physical": 0.0}}
    values = _values(levels, drop=("B", 3))
    configs = {r: _config("kinematic") for r in levels}
    rungs = [ladder.Rung(r, Path(r)) for r in ("A", "B", "C")]
    files = ladder_files(_read(values, configs), rungs, [ladder.Rung("D", Path("D"))], "cmd")
    trials = read_trial_data(io.BytesIO(files[ladder_data.FILE]))
    tests = pd.read_csv(io.BytesIO(files["ladder.csv"]))
    page = files["ladder.md"].decode()
    own = trials[trials["tested"] == "own"]
    ladder_seeds = set.intersection(*(set(own.loc[own["rung"] == r, "seed"]) for r in "ABC"))
    every = set(own["seed"])
    made = tests[tests["p"].notna()].to_dict("records")
    assert {r["kind"] for r in made} == {"step", "whole", "whole_all", "beside"}
    for case in made:
        seeds = ladder_seeds if case["kind"] in ("step", "whole") else every
        again = ladder_case(trials, case, seeds)
        for column, value in again.items():
            assert case[column] == pytest.approx(value, rel=1e-9), (case, column)
        if case["part"] == "step":
            assert f"{100 * again['mean']:+.1f} [{100 * again['low']:+.1f}, " in page
    # The rungs' means the page shows: over the seeds every rung holds.
    mean_a = own[(own["rung"] == "A") & own["seed"].isin(ladder_seeds)][KEY].mean()
    assert f"| ring 1 | {100 * mean_a:.1f} |" in page


def test_the_verdict_tells_rungs_holding_other_seeds_from_trials_missing_a_test_world():
    """Ends holding more seeds than the middle rungs, every trial tested in both worlds: the
    page says which seeds the steps use, not "Incomplete"; a trial missing a test world is."""
    from experiments.report.ladder_page import completeness_verdict

    values = _values(LEVELS, drop=("B", 3))
    verdict = completeness_verdict(ladder.completeness(values, ["A", "B", "C"]))
    assert "Incomplete" not in verdict
    assert "B lacks 3" in verdict and "Every step is taken on the seeds every rung holds" in verdict
    untested = values[~((values["rung"] == "C") & (values["tested"] == "physical"))]
    verdict = completeness_verdict(ladder.completeness(untested, ["A", "B", "C"]))
    assert verdict.startswith("Incomplete") and "C (physical)" in verdict


def test_of_two_rungs_the_whole_is_the_one_step_tested_once():
    """A ladder of two rungs has one step, which is its whole: the family tests it once (a
    duplicate would double Holm's m), and the page has no whole column or rows."""
    declared = ladder.family(["A", "B"], [], _headline(), ends_hold_more=False)
    assert set(declared["kind"]) == {"step"}
    assert not declared.duplicated(["key", "from", "to", "world", "part"]).any()
    values = _values({r: LEVELS[r] for r in ("A", "B")})
    steps = ladder.step_tests(values, ["A", "B"], [], _headline())
    splits = ladder.split_tests(values, ["A", "B"], [])
    assert len(steps) + len(splits) == len(declared)
    assert list(steps["kind"]) == ["step"]
