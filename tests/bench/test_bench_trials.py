"""`playroom bench trial`'s trials: timed, and the physical one says how many of its control
steps it computed (a movement at rest stops computing: sim/compiled_steps.py)."""

from __future__ import annotations

import math

import pytest

from experiments.bench.trials import trial_seconds_per_iteration
from sim.compiled_steps import AVAILABLE


@pytest.mark.skipif(not AVAILABLE, reason="MuJoCo's shared library not found")
def test_the_physical_trial_says_what_share_of_its_control_steps_it_computed():
    seconds, share = trial_seconds_per_iteration("physical", 60)
    assert seconds > 0
    # 60 iterations hold vocal movements in which nothing moves: they end early.
    assert 0.2 < share < 1.0


def test_a_kinematic_trial_computes_no_control_step():
    seconds, share = trial_seconds_per_iteration("kinematic", 20)
    assert seconds > 0 and math.isnan(share)
