"""The batch profiles shipped with the package (experiments/batches/profiles/*.json). Light: the
command line lists them in its help without importing what runs a batch."""

from __future__ import annotations

from importlib import resources


def stored_profiles() -> list[str]:
    """The batch profiles shipped in experiments/batches/profiles/, by name."""
    folder = resources.files("experiments.batches").joinpath("profiles")
    names = (f.name for f in folder.iterdir())
    return sorted(name.removesuffix(".json") for name in names if name.endswith(".json"))
