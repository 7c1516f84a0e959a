"""Argument types and errors of the `playroom` command line (experiments/cli/main.py)."""

from __future__ import annotations

import argparse
from typing import Any, NoReturn

from learner.config import LearnerConfig
from models.presets import DEFAULT_PRESET
from models.tracts import DEFAULT_TRACT
from sim.config import DEFAULT_WORLD
from sim.grasping.names import DEFAULT_GRASP

# What `playroom run` does when a setting is left out of a new trial (a resumed one keeps its
# own: experiments/run/settings.py). TrialSettings' own defaults are those of short trials.
RUN_DEFAULTS: dict[str, Any] = {
    "grasp": DEFAULT_GRASP,
    "iterations": 80000,
    "seed": 0,
    "babbling": LearnerConfig.babbling,
    "checkpoint_every": 1000,
    "stick_return": DEFAULT_WORLD.stick_return,
    "preset": DEFAULT_PRESET,
    "voice": DEFAULT_TRACT,
}


def run_default(name: str, more: str = "") -> str:
    """Help of a `run` option: its default for a new trial (a resumed trial keeps its own)."""
    return f"default: {RUN_DEFAULTS[name]}; with --resume: the trial's own{more}"


class UsageError(Exception):
    """A problem with what the user asked for: printed as one line, exit code 2."""


def non_negative_int(text: str) -> int:
    value = int(text)
    if value < 0:
        raise argparse.ArgumentTypeError(f"must be >= 0, got {value}")
    return value


def positive_int(text: str) -> int:
    value = int(text)
    if value <= 0:
        raise argparse.ArgumentTypeError(f"must be > 0, got {value}")
    return value


def iteration_list(text: str) -> list[int]:
    try:
        values = [int(v) for v in text.split(",") if v.strip()]
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected I,J,... integers, got {text!r}") from None
    if not values:
        raise argparse.ArgumentTypeError("no iteration given")
    return values


class Parser(argparse.ArgumentParser):
    """argparse, with errors on one line (exit code 2) instead of usage plus message."""

    def error(self, message: str) -> NoReturn:
        self.exit(2, f"{self.prog}: error: {message}\n")
