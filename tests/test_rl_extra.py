"""The `rl` extra (stable-baselines3, which brings torch) is for `make test-slow` alone: `make
test` and `make run` never install it, and the package itself never needs it."""

from __future__ import annotations

import re
import subprocess
import tomllib
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent


def _dry_run(target: str) -> str:
    # -B: every recipe, as on a fresh clone; -n: printed, not run.
    return subprocess.run(
        ["make", "-n", "-B", target], cwd=ROOT, capture_output=True, text=True, check=True
    ).stdout


def test_the_rl_extra_is_stable_baselines_and_recordvideos_writer_alone():
    project = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]
    assert project["optional-dependencies"]["rl"] == ["stable-baselines3>=2.3", "moviepy>=1.0.3,<2"]
    others = project["dependencies"] + project["optional-dependencies"]["dev"]
    assert not [d for d in others if d.startswith(("stable-baselines3", "torch", "moviepy"))]


def test_only_make_test_slow_installs_it_and_requires_its_checks_to_run():
    assert '".[rl]"' not in _dry_run("test") and '".[rl]"' not in _dry_run("run")
    slow = _dry_run("test-slow")
    assert '-e ".[rl]"' in slow
    # torch's CPU build: PyPI's default one brings gigabytes of CUDA libraries.
    assert f"--extra-index-url {_torch_index()} torch" in slow
    assert "PLAYROOM_RL_REQUIRED=1" in slow  # tests/sim/envs/test_env_sb3.py fails, not skips


def test_make_install_rl_installs_the_extra_with_torchs_cpu_build():
    install = _dry_run("install-rl")
    assert f"--constraint constraints.txt --extra-index-url {_torch_index()} torch" in install
    assert '--constraint constraints.txt -e ".[rl]"' in install
    assert '".[rl]"' not in _dry_run("install")


def test_the_docs_install_the_rl_extra_with_make_install_rl_only():
    # pip's own line brings torch with CUDA (gigabytes); `make install-rl` the CPU build.
    pages = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]
    told = {page.name: page.read_text() for page in pages}
    assert not [name for name, text in told.items() if re.search(r"pip install[^`\n]*\[rl\]", text)]
    assert "make install-rl" in told["README.md"] and "make install-rl" in told["rl-baseline.md"]


def _torch_index() -> str:
    (line,) = [
        line
        for line in (ROOT / "Makefile").read_text().splitlines()
        if line.startswith("TORCH_INDEX :=")
    ]
    return line.split(":=", 1)[1].strip()


def _lock_extra():
    import importlib.util

    spec = importlib.util.spec_from_file_location("lock_extra", ROOT / ".ci" / "lock_extra.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_make_lock_adds_the_extras_distributions_the_lock_lacks():
    report = {
        "install": [
            {"metadata": {"name": "stable_baselines3", "version": "2.9.2"}},
            {"metadata": {"name": "NumPy", "version": "2.4.6"}},
            {"metadata": {"name": "playroom", "version": "0.1.0"}},
            {"metadata": {"name": "torch", "version": "2.14.1"}},
        ]
    }
    lock = ["# a comment", "numpy==2.4.6", "Stable-Baselines3==2.9.2"]
    assert _lock_extra().added_pins(report, lock) == ["torch==2.14.1"]


def test_the_rl_extra_is_pinned_like_everything_else():
    pins = {
        line.split("==")[0].lower()
        for line in (ROOT / "constraints.txt").read_text().splitlines()
        if "==" in line
    }
    assert {"stable-baselines3", "torch", "moviepy"} <= {p.replace("_", "-") for p in pins}
    (torch,) = [line for line in (ROOT / "constraints.txt").read_text().splitlines()
                if line.startswith("torch==")]  # fmt: skip
    assert torch.endswith("+cpu")
    assert not [p for p in pins if p.startswith(("nvidia", "cuda"))]


@pytest.mark.slow  # pip resolves torch's and stable-baselines3's requirements: ~20 s
def test_every_distribution_the_rl_extra_brings_is_pinned(tmp_path):
    import json
    import sys

    report = tmp_path / "rl.json"
    subprocess.run(
        [sys.executable, "-m", "pip", "install", "--quiet", "--dry-run", "--ignore-installed",
         "--report", str(report), "--constraint", str(ROOT / "constraints.txt"),
         "--extra-index-url", _torch_index(), "--retries", "1", f"{ROOT}[rl]"],
        check=True, capture_output=True,
    )  # fmt: skip
    lock = (ROOT / "constraints.txt").read_text().splitlines()
    assert _lock_extra().added_pins(json.loads(report.read_text()), lock) == []
