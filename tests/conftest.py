"""Shared test setup.

No OpenGL backend is chosen for the suite: most tests never render, and they run with the
user's `MUJOCO_GL`, unset on most machines, as non-rendering commands do. The tests that render
in this process choose their backend themselves (tests/video/conftest.py), those that run
`playroom render` in a subprocess leave it to the command (experiments/video/gl.py).
"""

import os

import pytest

# A generated DIVA map installed for a test (the real one is the user's): used across stages.
from diva_files import installed_generated_map  # noqa: F401


@pytest.fixture(autouse=True)
def gl_choice_kept():
    """A command run in this process (`main([...])`) chooses MUJOCO_GL for the process, as
    `playroom` does for its own (experiments/video/gl.py): put it back after each test, so that
    one test's choice never reaches the next one's subprocesses."""
    before = os.environ.get("MUJOCO_GL")
    yield
    if before is None:
        os.environ.pop("MUJOCO_GL", None)
    else:
        os.environ["MUJOCO_GL"] = before


@pytest.fixture(scope="session", autouse=True)
def reference_cache(tmp_path_factory):
    """Reports keep their played references in a folder of the session, not the user's cache
    (experiments.measure.study_measure.CACHE_ENV, named here so that nothing heavy is imported
    before the tests choose; subprocesses inherit it)."""
    with pytest.MonkeyPatch.context() as patch:
        patch.setenv("PLAYROOM_CACHE_DIR", str(tmp_path_factory.mktemp("reference-cache")))
        yield


@pytest.fixture(scope="session")
def savez_round_trip():
    """state dict -> the same dict written by np.savez and read back, as checkpoints are."""
    import io

    import numpy as np

    def round_trip(state: dict) -> dict:
        buffer = io.BytesIO()
        np.savez(buffer, **state)
        buffer.seek(0)
        with np.load(buffer, allow_pickle=False) as loaded:
            return {key: loaded[key] for key in loaded.files}

    return round_trip


@pytest.fixture(scope="session")
def trained_trial(tmp_path_factory):
    """One short kinematic trial, trained once for the whole session: 3000 iterations, seed 0,
    checkpoints every 1000. Its `.dir` holds the trial. Tests only read it: one that writes
    into a trial copies `.dir` first (shutil.copytree)."""
    from experiments.run.settings import TrialSettings
    from experiments.run.trial import run_trial

    settings = TrialSettings(grasp="kinematic", iterations=3000, seed=0, checkpoint_every=1000)
    return run_trial(tmp_path_factory.mktemp("trained") / "trial", settings, progress=False)


@pytest.fixture(scope="session")
def batches(tmp_path_factory):
    """Two tiny batches, one per grasp backend: kinematic seeds 0 and 1, physical seed 0
    (300 iterations, evaluated on 3 placements), each with the record (batch.json) that
    `playroom batch` writes. Tests only read them."""
    from experiments.batch_files import BATCH_FILE
    from experiments.batches.spec import BatchSpec, spec_record
    from experiments.measure.evaluation import EvaluationSettings
    from experiments.measure.trial_evaluation import evaluate_trial
    from experiments.run.trial import run_trial
    from experiments.trial_dir import storage

    root = tmp_path_factory.mktemp("batches")
    out = {}
    for grasp, seeds in (("kinematic", (0, 1)), ("physical", (0,))):
        batch = root / grasp
        spec = BatchSpec(
            grasps=(grasp,), seeds=seeds, iterations=300, checkpoint_every=300, eval_placements=3
        )
        for name, settings in spec.trials():
            run_trial(batch / name, settings, progress=False)
            evaluate_trial(batch / name, EvaluationSettings(n_placements=spec.eval_placements))
        storage.write_json(batch / BATCH_FILE, spec_record(spec))
        out[grasp] = batch
    return out


@pytest.fixture
def run_without_numba_cache(tmp_path):
    """Run Python code in a process where numba finds no cache directory, as in a read-only
    install without a writable home (its only allowed one is a path under a file): returns
    what the code printed; asserts it ran and that no cache was made."""
    import subprocess
    import sys

    blocker = tmp_path / "a-file"
    blocker.write_text("")
    env = dict(
        os.environ,
        NUMBA_CACHE_LOCATOR_CLASSES="UserProvidedCacheLocator",
        NUMBA_CACHE_DIR=str(blocker / "cache"),
    )

    def run(code: str) -> str:
        result = subprocess.run(
            [sys.executable, "-c", code], capture_output=True, text=True, env=env
        )
        assert result.returncode == 0, result.stderr
        assert not (blocker.parent / "cache").exists()
        return result.stdout.strip()

    return run
