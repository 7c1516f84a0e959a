"""Trials shared by the tests of a module of tests/run/."""

import pytest
from trial_states import SEGMENTED


@pytest.fixture(scope="module")
def segmented_trial(tmp_path_factory):
    """An uninterrupted, evaluated SEGMENTED trial: tests compare against it, and write into
    copies of it."""
    from experiments.measure.evaluation import EvaluationSettings
    from experiments.measure.trial_evaluation import evaluate_trial
    from experiments.run.trial import run_trial

    out = tmp_path_factory.mktemp("segmented") / "trial"
    run_trial(out, SEGMENTED, progress=False)
    evaluate_trial(out, EvaluationSettings(n_placements=1))
    return out
