"""The `cluster` extra (dask-jobqueue, for `playroom cluster`) is pinned like everything else,
kept pinned by `make lock`, and installed by `make test`, whose suite checks its job scripts."""

from __future__ import annotations

import json
import subprocess
import sys
import tomllib
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent


def _extras() -> dict[str, list[str]]:
    return tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]["optional-dependencies"]


def _pins() -> dict[str, str]:
    lines = (ROOT / "constraints.txt").read_text().splitlines()
    return dict(line.lower().replace("_", "-").split("==") for line in lines if "==" in line)


def _dry_run(target: str) -> str:
    # -B: every recipe, as on a fresh clone; -n: printed, not run.
    return subprocess.run(
        ["make", "-n", "-B", target], cwd=ROOT, capture_output=True, text=True, check=True
    ).stdout


def test_the_cluster_extra_is_dask_jobqueue_pinned_beside_dask():
    assert _extras()["cluster"] == ["dask-jobqueue>=0.9"]
    pins = _pins()
    assert "dask-jobqueue" in pins
    assert {"dask", "distributed"} <= set(pins)  # the versions it was resolved against


def test_make_test_installs_it_and_make_lock_keeps_it_pinned():
    # The dev extra holds the cluster extra, so that `make test` (a fresh clone's CI) runs the
    # job scripts' tests; `make lock` resolves both.
    assert set(_extras()["cluster"]) <= set(_extras()["dev"])
    assert '-e ".[dev]"' in _dry_run("test")
    assert '".[dev,cluster]"' in _dry_run("lock")


def _lock_extra():
    import importlib.util

    spec = importlib.util.spec_from_file_location("lock_extra", ROOT / ".ci" / "lock_extra.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


@pytest.mark.slow  # pip resolves the project's requirements from the index: ~10 s
def test_every_distribution_the_cluster_extra_brings_is_pinned(tmp_path):
    report = tmp_path / "cluster.json"
    subprocess.run(
        [sys.executable, "-m", "pip", "install", "--quiet", "--dry-run", "--ignore-installed",
         "--report", str(report), "--constraint", str(ROOT / "constraints.txt"),
         "--retries", "1", f"{ROOT}[cluster]"],
        check=True, capture_output=True,
    )  # fmt: skip
    lock = (ROOT / "constraints.txt").read_text().splitlines()
    assert _lock_extra().added_pins(json.loads(report.read_text()), lock) == []
