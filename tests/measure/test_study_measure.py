"""The study's own measure (experiments/measure/study_measure.py), its quirks included."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from experiments.analysis.study_maps import GRID, competence_map, reference_map, strategy_curve
from experiments.analysis.study_summary import FULL_COVERAGE, study_summary
from experiments.measure.study_measure import (
    StudyMeasureSettings,
    _arm_context_of_the_study,
    random_reference,
    study_tests,
)
from experiments.run.trial_parts import load_trial
from sim.config import world_preset

# The world these tests were written for: the project preset (explicit, as Playroom() takes
# the default preset, the study's).
PROJECT = world_preset("project")


def test_the_map_normalises_each_pixel_by_the_random_error_around_its_distance():
    # Two tests in one pixel (errors 0.2 and 0.4), one in another (error 3.0). The reference
    # holds one command in a pixel at the first one's distance (error 1.0), two in one pixel
    # at the second's (errors 1.0 and 3.0: that pixel's mean is 2.0).
    tests = pd.DataFrame({"x": [0.3, 0.3, -0.7], "y": [0.0, 0.0, 0.0], "error": [0.2, 0.4, 3.0]})
    reference = pd.DataFrame({"x": [0.0, 0.7, 0.7], "y": [0.3, 0.0, 0.0], "error": [1.0, 1.0, 3.0]})
    grid = competence_map(tests, reference)
    i = int((0.3 + 1) / 2 * GRID)
    assert grid[i, GRID // 2] == pytest.approx(1 - 0.3 / 1.0)
    assert grid[int((-0.7 + 1) / 2 * GRID), GRID // 2] == 0.0  # worse than random: clipped at 0
    assert np.isnan(grid).sum() == GRID * GRID - 2


def test_the_reference_is_the_mean_of_pixel_means_within_one_pixel_of_distance():
    """The notebook's rule, written as it reads: for a pixel at distance d from (50, 50), the
    unweighted mean of the per-pixel means above 0 of the pixels at distances in (d-1, d+1)."""
    rng = np.random.default_rng(3)
    reference = pd.DataFrame(
        {
            "x": rng.uniform(-1, 1, 4000),
            "y": rng.uniform(-1, 1, 4000),
            "error": rng.uniform(0.0, 2.0, 4000),
        }
    )
    reference.loc[:100, "error"] = 0.0  # pixels whose mean is 0 are left out, as the study did
    sums, counts = np.zeros((GRID, GRID)), np.zeros((GRID, GRID))
    for x, y, e in reference[["x", "y", "error"]].itertuples(index=False):
        i, j = min(int((x + 1) / 2 * 100), 99), min(int((y + 1) / 2 * 100), 99)
        sums[i, j] += e
        counts[i, j] += 1
    means = np.where(counts > 0, sums / np.maximum(counts, 1), -1.0)
    gi, gj = np.meshgrid(np.arange(GRID), np.arange(GRID), indexing="ij")
    distance = np.sqrt((gi - 50) ** 2 + (gj - 50) ** 2)
    got = reference_map(reference)
    for i, j in rng.integers(0, GRID, (40, 2)):
        d = distance[i, j]
        similar = (d - 1 < distance) & (distance < d + 1) & (means > 0)
        assert got[i, j] == pytest.approx(means[similar].mean())


def test_the_strategy_curve_averages_pixels_then_renormalises_in_sequence():
    # One pixel at distance 10 pixels from the centre holds a hand and a vocal test; the
    # other pixels of that bin hold none and count 0.
    x = (60 + 0.5) / 50 - 1  # pixel i = 60, j = 50: distance 10
    tests = pd.DataFrame({"x": [x, x], "y": [0.01, 0.01], "strategy": ["hand", "vocal"]})
    curve = strategy_curve(tests)
    gi, gj = np.meshgrid(np.arange(GRID), np.arange(GRID), indexing="ij")
    n = (np.sqrt((gi - 50) ** 2 + (gj - 50) ** 2).astype(int) == 10).sum()
    hand, vocal = 0.5 / n, 0.5 / n
    hand = hand / (hand + 0.0 + vocal)  # the notebook's order: hand first, with the old sum
    vocal = vocal / (hand + 0.0 + vocal)  # then vocal, with the renormalised hand share
    assert curve.loc[10, "hand"] == pytest.approx(0.5)
    assert curve.loc[10, "vocal"] == pytest.approx(vocal) and vocal < 0.5
    assert curve.loc[10, "tool"] == 0.0
    assert len(curve) == 50 and curve["x"].iloc[-1] == 1.0
    assert curve.drop(index=10)[["hand", "tool", "vocal"]].isna().all().all()  # 0 / 0


def test_placements_are_drawn_from_each_trials_seed():
    from learner.agent import Agent
    from learner.config import LearnerConfig
    from sim import Playroom

    settings = StudyMeasureSettings(n_placements=2)

    def positions(seed: int) -> np.ndarray:
        tests = study_tests(
            Agent(LearnerConfig(), 0), Playroom("kinematic", seed=seed, config=PROJECT), settings
        )
        return tests[["x", "y"]].to_numpy()

    assert np.array_equal(positions(1), positions(1))
    assert not np.array_equal(positions(1), positions(2))


def test_the_arm_model_is_asked_with_the_voice_models_context_values():
    context = np.arange(10.0)  # stick 0 1, toy1 2 3, toy2 4 5, toy3 6 7, caregiver 8 9
    swapped = _arm_context_of_the_study(context, "toy2")
    assert list(swapped[0:2]) == [4, 5] and list(swapped[4:6]) == [8, 9]


def test_tests_and_reference_on_a_trained_trial(trained_trial):
    config, agent, room, _ = load_trial(trained_trial.dir)
    settings = StudyMeasureSettings(n_placements=2, random_commands_per_ring=9)
    tests = study_tests(agent, room, settings)
    assert len(tests) == 3 * 2 * 3 and set(tests["strategy"]) <= {"hand", "tool", "vocal"}
    assert (np.hypot(tests["x"], tests["y"]) <= 1.0).all() and np.isfinite(tests["error"]).all()
    reference = random_reference({"kinematic": config}, settings, workers=1)["kinematic"]
    assert len(reference) == 3 * 9 and np.isfinite(reference["error"]).all()
    summary = study_summary(tests, reference)
    assert set(summary["competence"]) == {"all", "ring1", "ring2", "ring3"}
    assert 0.0 <= summary["competence"]["all"] <= 1.0


def _one_test_per_disk_pixel(rng: np.random.Generator) -> pd.DataFrame:
    """A run whose tests cover every pixel of the disk, one test each."""
    centres = (np.arange(GRID) + 0.5) / (GRID / 2) - 1.0
    x, y = (a.ravel() for a in np.meshgrid(centres, centres, indexing="ij"))
    inside = np.hypot(x, y) < 1.0
    n = int(inside.sum())
    return pd.DataFrame(
        {
            "x": x[inside],
            "y": y[inside],
            "error": rng.uniform(0.0, 1.0, n),
            "strategy": rng.choice(["hand", "tool", "vocal"], n),
            "ring": rng.integers(1, 4, n),
        }
    )


def test_intervals_resample_runs_and_vanish_when_runs_agree():
    rng = np.random.default_rng(5)
    one_run = _one_test_per_disk_pixel(rng)
    reference = one_run.assign(error=1.0)
    copies = pd.concat([one_run.assign(trial=f"t{k}") for k in range(4)], ignore_index=True)
    summary = study_summary(copies, reference)
    assert summary["coverage"] == pytest.approx(1.0, abs=0.01)
    low, high = summary["intervals"]["competence_all"]
    assert low == pytest.approx(summary["competence"]["all"]) == pytest.approx(high)
    assert "intervals" not in study_summary(one_run.assign(trial="t0"), reference)
    differing = copies.copy()
    differing.loc[differing["trial"] == "t0", "error"] *= 0.5  # one run much better
    summary = study_summary(differing, reference)
    low, high = summary["intervals"]["competence_all"]
    assert low < summary["competence"]["all"] < high
    low, high = summary["intervals"]["strategy_share"]["centre"]["hand"]
    share = summary["strategy_share"]["centre"]["hand"]
    assert 0.0 <= low <= share + 1e-12 and share - 1e-12 <= high <= 1.0


def test_coverage_counts_the_disk_pixels_holding_a_test():
    tests = pd.DataFrame(
        {
            "x": [0.3, 0.3, -0.7],
            "y": [0.0, 0.0, 0.0],
            "error": [0.2, 0.4, 3.0],
            "strategy": ["hand", "tool", "vocal"],
            "ring": [1, 1, 3],
        }
    )
    gi, gj = np.meshgrid(np.arange(GRID), np.arange(GRID), indexing="ij")
    disk = (np.sqrt((gi - 50) ** 2 + (gj - 50) ** 2) < 50).sum()
    summary = study_summary(tests, tests.assign(error=1.0))
    assert summary["coverage"] == pytest.approx(2 / disk)


def test_no_intervals_where_the_tests_cover_too_few_pixels():
    """A resample repeats runs and covers fewer pixels, which lowers every renormalised
    share: below FULL_COVERAGE the intervals would miss their own estimates, so there are
    none."""
    rng = np.random.default_rng(6)
    runs = []
    for k in range(4):  # each run covers a random quarter of the disk's pixels
        run = _one_test_per_disk_pixel(rng)
        runs.append(run[rng.random(len(run)) < 1 / 4].assign(trial=f"t{k}"))
    tests = pd.concat(runs, ignore_index=True)
    summary = study_summary(tests, tests.assign(error=1.0))
    assert summary["coverage"] < FULL_COVERAGE and "intervals" not in summary
    assert 0.0 <= summary["competence"]["all"] <= 1.0
