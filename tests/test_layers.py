"""Reading results and drawing pages load no simulator: analysis runs on any machine, quickly
(the layering itself is checked by `make lint`: pyproject.toml's [tool.importlinter])."""

from __future__ import annotations

import subprocess
import sys

import pytest

HEAVY = ("mujoco", "dm_control", "numba", "sim", "learner")


@pytest.mark.parametrize(
    "module",
    ["experiments.analysis.results", "experiments.analysis.stats", "experiments.report.comparison"],
)
def test_analysis_and_reports_import_no_simulator(module):
    code = f"import sys, {module}; print(' '.join(m for m in {HEAVY!r} if m in sys.modules))"
    loaded = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, check=True
    )
    assert loaded.stdout.strip() == ""
