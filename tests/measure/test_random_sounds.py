"""Random vocal commands in each tract (`playroom sounds`): the same commands heard by each."""

from __future__ import annotations

import numpy as np
import pytest

from experiments.cli.main import main
from experiments.measure.random_sounds import random_sound_table
from models.presets import DEFAULT_PRESET
from sim.config import world_preset
from sim.vocal.diva.tract import DivaTract


def test_each_tract_hears_the_same_commands(installed_generated_map) -> None:
    table = random_sound_table(("vtl", "diva"), n_commands=40, seed=3)
    assert list(table.index) == ["vtl", "diva"]
    tract = DivaTract(fit=installed_generated_map, world=world_preset(DEFAULT_PRESET, voice="diva"))
    commands = np.random.default_rng(3).uniform(-1.0, 1.0, (40, 28))
    distances = np.stack([tract.word_distances(tract.sound_features(m)) for m in commands])
    row = table.loc["diva"]
    assert row["best_oey"] == pytest.approx(distances[:, 0].min())
    assert row["median_nearest"] == pytest.approx(np.median(distances.min(axis=1)))
    assert row["within_recognition"] == pytest.approx(np.mean(distances.min(axis=1) < 0.4))


def test_bad_requests_are_refused(capsys) -> None:
    with pytest.raises(ValueError, match="n_commands must be a positive integer"):
        random_sound_table(("vtl",), n_commands=0)
    with pytest.raises(ValueError, match="unknown vocal tracts"):
        random_sound_table(("dive",))
    assert main(["sounds", "--voice", "vtl", "--commands", "20"]) == 0
    out = capsys.readouterr().out
    assert "20 random vocal commands" in out and "median_nearest" in out
