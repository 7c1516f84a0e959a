"""The evaluation tables recorded before the measures asked actors (experiments/measure/
actors.py), that tests/measure/test_actors.py compares the code of now against: a short
kinematic trial of the project preset (its agent moves toys within 2000 iterations, and uses
the stick in some tests; the kinematic backend gives the same bits on every CPU:
tests/reference_trials.py), evaluated on 3 placements per ring.

Recorded from the checkout of commit f31f4e9 (the last one before), on the 2-core development
machine, 2026-11-27:
    PYTHONPATH=CHECKOUT python tests/measure/before_actors.py
"""

from __future__ import annotations

import shutil
import sys
import tempfile
from pathlib import Path

DATA = Path(__file__).resolve().parents[1] / "data"
SEED, ITERATIONS, PLACEMENTS = 0, 2000, 3
TABLES = ("competence.parquet", "study-tests.parquet")


def recorded(name: str) -> Path:
    return DATA / f"before-actors-kinematic-seed{SEED}-{ITERATIONS}-{name}"


def evaluated_trial(out: Path) -> Path:
    """The trial, run and evaluated into `out` by the code on the path."""
    from experiments.measure.evaluation import EvaluationSettings
    from experiments.measure.trial_evaluation import evaluate_trial
    from experiments.run.settings import TrialSettings
    from experiments.run.trial import run_trial

    settings = TrialSettings(
        grasp="kinematic",
        iterations=ITERATIONS,
        seed=SEED,
        checkpoint_every=ITERATIONS,
        preset="project",
    )
    run_trial(out, settings, progress=False)
    evaluate_trial(out, EvaluationSettings(n_placements=PLACEMENTS))
    return out


if __name__ == "__main__":
    with tempfile.TemporaryDirectory() as tmp:
        trial = evaluated_trial(Path(tmp) / "trial")
        for name in TABLES:
            shutil.copyfile(trial / name, recorded(name))
            print(f"written: {recorded(name)}", file=sys.stderr)
