"""The `rl` extra (stable-baselines3) for the slow checks: skipped without it, unless `make
test-slow` (which installs it) sets REQUIRED, where a missing library fails instead."""

import importlib.util
import os

import pytest

REQUIRED = "PLAYROOM_RL_REQUIRED"


def require_stable_baselines3() -> None:
    """Skip the calling test module (at its import) where stable-baselines3 is missing."""
    if importlib.util.find_spec("stable_baselines3") is not None:
        return
    if os.environ.get(REQUIRED):
        raise ImportError("stable-baselines3 is not installed, and make test-slow requires it")
    pytest.skip(
        "stable-baselines3 is not installed: `make test-slow` installs it (the `rl` extra)",
        allow_module_level=True,
    )
