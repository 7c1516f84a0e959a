"""Argument types and errors of the `playroom` command line (experiments/cli.py)."""

from __future__ import annotations

import argparse
from importlib import resources


def stored_profiles() -> list[str]:
    """The batch profiles shipped in experiments/profiles/, by name."""
    folder = resources.files("experiments").joinpath("profiles")
    names = (f.name for f in folder.iterdir())
    return sorted(name.removesuffix(".json") for name in names if name.endswith(".json"))


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

    def error(self, message: str) -> None:
        self.exit(2, f"{self.prog}: error: {message}\n")
