"""Refactoring changes no behaviour: a 2000-iteration trial of each backend gives the logs it
gave when they were recorded (tests/data, recorded 2026-11-22, before the code was reorganised into
models/layout.py, one loop and one caregiver, by running the same settings)."""

from __future__ import annotations

from pathlib import Path

import pandas as pd
import pytest

from experiments.trial import TrialSettings, read_log, run_trial

DATA = Path(__file__).parent / "data"
SEED, ITERATIONS = 11, 2000


@pytest.mark.parametrize("grasp", ["kinematic", "physical"])
def test_same_seed_same_logs_as_recorded(tmp_path, grasp):
    out = tmp_path / grasp
    settings = TrialSettings(grasp=grasp, iterations=ITERATIONS, seed=SEED, checkpoint_every=1000)
    run_trial(out, settings, progress=False)
    for kind in ("iterations", "words"):
        recorded = pd.read_parquet(
            DATA / f"reference-{grasp}-seed{SEED}-{ITERATIONS}-{kind}.parquet"
        )
        pd.testing.assert_frame_equal(read_log(out, kind), recorded, check_dtype=False)
