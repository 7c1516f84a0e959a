"""Shared test setup.

MuJoCo picks its OpenGL backend when `mujoco` is first imported, and the video tests render
offscreen in this process: choose EGL here, before any test module imports mujoco (the
`playroom` command does the same per command, experiments/gl.py).
"""

import os

os.environ.setdefault("MUJOCO_GL", "egl")

import pytest  # noqa: E402


@pytest.fixture(scope="session")
def trained_trial(tmp_path_factory):
    """One short kinematic trial, trained once for the whole session: 3000 iterations, seed 0,
    checkpoints every 1000. Its `.dir` holds the trial. Tests only read it: one that writes
    into a trial copies `.dir` first (shutil.copytree)."""
    from experiments.trial import TrialSettings, run_trial

    settings = TrialSettings(grasp="kinematic", iterations=3000, seed=0, checkpoint_every=1000)
    return run_trial(tmp_path_factory.mktemp("trained") / "trial", settings, progress=False)
