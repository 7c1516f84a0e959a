"""The study's own measure (experiments/study_measure.py), its quirks included."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from experiments.study_measure import (
    GRID,
    StudyMeasureSettings,
    _arm_context_of_the_study,
    competence_map,
    random_reference,
    study_summary,
    study_tests,
)
from experiments.trial import load_trial


def test_the_map_normalises_each_pixel_by_the_random_error_of_its_ring():
    # Two tests in one pixel (errors 0.2 and 0.4), one in another (error 3.0); the random
    # reference has error 1.0 at the first pixel's distance and 2.0 at the second's.
    tests = pd.DataFrame({"x": [0.3, 0.3, -0.7], "y": [0.0, 0.0, 0.0], "error": [0.2, 0.4, 3.0]})
    reference = pd.DataFrame({"x": [0.0, -0.3, 0.7], "y": [0.3, 0.0, 0.0], "error": [1, 1, 2.0]})
    grid = competence_map(tests, reference)
    i = int((0.3 + 1) / 2 * GRID)
    assert grid[i, GRID // 2] == pytest.approx(1 - 0.3 / 1.0)
    assert grid[int((-0.7 + 1) / 2 * GRID), GRID // 2] == 0.0  # worse than random: clipped at 0
    assert np.isnan(grid).sum() == GRID * GRID - 2


def test_the_arm_model_is_asked_with_the_voice_models_context_values():
    context = np.arange(10.0)  # stick 0 1, toy1 2 3, toy2 4 5, toy3 6 7, caregiver 8 9
    swapped = _arm_context_of_the_study(context, "toy2")
    assert list(swapped[0:2]) == [4, 5] and list(swapped[4:6]) == [8, 9]


def test_tests_and_reference_on_a_trained_trial(trained_trial):
    _, agent, room, _ = load_trial(trained_trial.dir)
    settings = StudyMeasureSettings(n_placements=2, random_commands_per_ring=9)
    tests = study_tests(agent, room, settings)
    assert len(tests) == 3 * 2 * 3 and set(tests["strategy"]) <= {"hand", "tool", "vocal"}
    assert (np.hypot(tests["x"], tests["y"]) <= 1.0).all() and np.isfinite(tests["error"]).all()
    reference = random_reference(room, settings)
    assert len(reference) == 3 * 9 and np.isfinite(reference["error"]).all()
    summary = study_summary(tests, reference)
    assert set(summary["competence"]) == {"all", "ring1", "ring2", "ring3"}
    assert 0.0 <= summary["competence"]["all"] <= 1.0
