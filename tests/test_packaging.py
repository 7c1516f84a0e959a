"""The package as a user installs it: a wheel, in a fresh environment, away from the repository."""

from __future__ import annotations

import json
import os
import re
import shutil
import subprocess
import sys
import sysconfig
import zipfile
from pathlib import Path

import pytest

REPO = Path(__file__).parent.parent
# What a wheel is built from: the project's files, without the repository's other contents.
SOURCES = ("pyproject.toml", "README.md", "LICENSE", "models", "sim", "learner", "experiments")


def _build_wheel(tmp_path: Path) -> Path:
    source = tmp_path / "source"
    source.mkdir()
    for name in SOURCES:
        if (REPO / name).is_dir():
            shutil.copytree(
                REPO / name, source / name, ignore=shutil.ignore_patterns("__pycache__")
            )
        else:
            shutil.copy2(REPO / name, source / name)
    dist = tmp_path / "dist"
    subprocess.run(
        [sys.executable, "-m", "pip", "wheel", "--no-deps", "--no-build-isolation", "--quiet",
         "--wheel-dir", str(dist), str(source)],
        check=True, capture_output=True,
    )  # fmt: skip
    (wheel,) = dist.glob("playroom-*.whl")
    return wheel


def test_the_wheel_ships_the_model_and_data_and_no_dev_tools(tmp_path):
    wheel = _build_wheel(tmp_path)
    with zipfile.ZipFile(wheel) as archive:
        names = set(archive.namelist())
        metadata = archive.read(next(n for n in names if n.endswith("METADATA"))).decode()
    assert "models/playroom.xml" in names
    assert {f"{p}/py.typed" for p in ("models", "sim", "learner", "experiments")} <= names
    (licence,) = [n for n in names if n.endswith(".dist-info/licenses/LICENSE")]
    with zipfile.ZipFile(wheel) as archive:
        assert archive.read(licence).startswith(b"                    GNU GENERAL PUBLIC")
    voice_data = ("articulators", "formant_map", "productions", "vowels")
    assert {f"sim/vocal/vtl/data/{n}.npz" for n in voice_data} <= names
    assert "experiments/batches/profiles/demo.json" in names
    assert {"sim/envs/__init__.py", "sim/envs/dm_env_movement.py", "sim/envs/gym_env.py"} <= names
    # The voice's build-time fitting script is not installed (pyproject.toml excludes it).
    assert not [n for n in names if n.startswith("sim/vocal/vtl/fitting")]
    requires = [line for line in metadata.splitlines() if line.startswith("Requires-Dist:")]
    for tool in ("pytest", "pytest-xdist", "ruff", "mypy"):
        (line,) = [r for r in requires if re.split(r"[<>=!~; \[]", r.split()[1])[0] == tool]
        assert 'extra == "dev"' in line, line


@pytest.mark.slow  # over 5 s: make test-slow runs it
def test_an_installed_wheel_runs_a_trial_outside_the_repository(tmp_path):
    wheel = _build_wheel(tmp_path)
    env_dir = tmp_path / "fresh-env"
    subprocess.run([sys.executable, "-m", "venv", "--without-pip", str(env_dir)], check=True)
    python = env_dir / "bin" / "python"
    subprocess.run(
        [sys.executable, "-m", "pip", "--python", str(python), "install", "--no-deps",
         "--no-index", "--quiet", str(wheel)],
        check=True, capture_output=True,
    )  # fmt: skip
    # The dependencies come from this environment's site-packages as a plain path: its .pth
    # files (among them the editable install's link to the repository) are not read.
    purelib = subprocess.run(
        [python, "-c", "import sysconfig; print(sysconfig.get_paths()['purelib'])"],
        check=True, capture_output=True, text=True,
    ).stdout.strip()  # fmt: skip
    Path(purelib, "test-dependencies.pth").write_text(sysconfig.get_paths()["purelib"] + "\n")
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "MUJOCO_GL")}
    work = tmp_path / "elsewhere"
    work.mkdir()
    where = subprocess.run(
        [python, "-c", "import models, sim, experiments; print(models.__file__, sim.__file__)"],
        check=True, capture_output=True, text=True, cwd=work, env=env,
    ).stdout  # fmt: skip
    assert str(REPO) not in where and str(env_dir) in where
    # The memory's compiled kernel, compiled and cached from the installed package.
    query = (
        "import numpy as np, learner.memory as m\n"
        "rows = np.random.default_rng(0).uniform(-1, 1, (2000, 10))\n"
        "memory = m.NearestNeighbourMemory(10)\n"
        "memory.extend(rows)\n"
        "q = np.linspace(-1, 1, 10)\n"
        "assert memory.nearest(q) == m.brute_force_nearest(rows, q)\n"
        "print(m.__file__)\n"
    )
    kernel = subprocess.run(
        [python, "-c", query], capture_output=True, text=True, cwd=work, env=env
    )
    assert kernel.returncode == 0, kernel.stderr
    assert str(env_dir) in kernel.stdout
    result = subprocess.run(
        [env_dir / "bin" / "playroom", "run", "--grasp", "physical", "--iterations", "25",
         "--out", str(work / "trial"), "--quiet"],
        capture_output=True, text=True, cwd=work, env=env,
    )  # fmt: skip
    assert result.returncode == 0, result.stderr
    assert "25 iterations (physical" in result.stdout
    # An installed package has no commit to record: its provenance says where it came from.
    entries = json.loads((work / "trial" / "provenance.json").read_text())
    assert entries[0]["record"]["source"] == {
        "commit": None,
        "dirty": None,
        "where": "installed package",
    }
