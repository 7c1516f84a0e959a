"""The `rl` extra (stable-baselines3) for the slow checks: skipped without it, unless `make
test-slow` (which installs it) sets REQUIRED, where a missing library fails instead."""

import importlib.util
import os

import pytest

REQUIRED = "PLAYROOM_RL_REQUIRED"


def require_stable_baselines3() -> None:
    """Skip the calling test module (at its import) where stable-baselines3 is missing."""
    require("stable_baselines3")


def require(module: str) -> None:
    """Skip the calling test (or test module, at its import) where `module`, one of the `rl`
    extra's, is missing; fail instead under `make test-slow`."""
    if importlib.util.find_spec(module) is not None:
        return
    if os.environ.get(REQUIRED):
        raise ImportError(f"{module} is not installed, and make test-slow requires it")
    pytest.skip(
        f"{module} is not installed: `make test-slow` installs it (the `rl` extra)",
        allow_module_level=True,
    )
