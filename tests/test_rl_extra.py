"""The `rl` extra (stable-baselines3, which brings torch) is for `make test-slow` alone: `make
test` and `make run` never install it, and the package itself never needs it."""

from __future__ import annotations

import subprocess
import tomllib
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent


def _dry_run(target: str) -> str:
    # -B: every recipe, as on a fresh clone; -n: printed, not run.
    return subprocess.run(
        ["make", "-n", "-B", target], cwd=ROOT, capture_output=True, text=True, check=True
    ).stdout


def test_the_rl_extra_is_stable_baselines_alone():
    project = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]
    assert project["optional-dependencies"]["rl"] == ["stable-baselines3>=2.3"]
    others = project["dependencies"] + project["optional-dependencies"]["dev"]
    assert not [d for d in others if d.startswith(("stable-baselines3", "torch"))]


def test_only_make_test_slow_installs_it_and_requires_its_checks_to_run():
    assert '".[rl]"' not in _dry_run("test") and '".[rl]"' not in _dry_run("run")
    slow = _dry_run("test-slow")
    assert '-e ".[rl]"' in slow
    assert "PLAYROOM_RL_REQUIRED=1" in slow  # tests/sim/envs/test_env_sb3.py fails, not skips
