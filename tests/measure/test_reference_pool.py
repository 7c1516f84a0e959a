"""The study's random reference played in chunks on a pool of processes
(experiments/measure/reference_pool.py): the same rows whatever the number of processes, each
chunk its own, and a reference kept in the cache read back without playing."""

from __future__ import annotations

import json
from types import SimpleNamespace

import numpy as np
import pandas as pd
import pytest

from experiments.measure import reference_pool, study_measure
from experiments.measure.reference_pool import chunks_of, play_chunk, play_references
from experiments.run.settings import TrialSettings
from experiments.run.trial_config import full_config

SEED = 7
COMMANDS = 60  # per ring
CHUNK = 15  # commands per chunk: 4 chunks per ring


def _config(grasp: str) -> dict:
    return full_config(TrialSettings(grasp=grasp, seed=0))


def test_chunks_cut_each_ring_the_last_holding_what_is_left():
    chunks = chunks_of("g", rings=2, commands_per_ring=10, chunk_commands=4)
    assert [(c.ring, c.index, c.commands) for c in chunks] == [
        (0, 0, 4), (0, 1, 4), (0, 2, 2), (1, 0, 4), (1, 1, 4), (1, 2, 2),
    ]  # fmt: skip
    with pytest.raises(ValueError, match="chunk_commands"):
        chunks_of("g", rings=1, commands_per_ring=10, chunk_commands=0)


def test_the_reference_is_the_same_on_one_process_and_on_two(monkeypatch):
    # Both backends' chunks on one pool, as `compare` plays them; the pool is used even for
    # this small reference (this process plays short ones itself).
    configs = {"kinematic": _config("kinematic"), "physical": _config("physical")}
    alone = play_references(configs, SEED, COMMANDS, workers=1, chunk_commands=CHUNK)
    monkeypatch.setattr(reference_pool, "POOL_MIN_COMMANDS", 0)
    pooled = play_references(configs, SEED, COMMANDS, workers=2, chunk_commands=CHUNK)
    assert list(pooled) == list(configs)
    for group in configs:
        assert len(alone[group]) == 3 * COMMANDS
        pd.testing.assert_frame_equal(alone[group], pooled[group])
        assert np.isfinite(pooled[group]["error"]).all()
    # The seed reaches every chunk.
    other = play_references(configs, SEED + 1, COMMANDS, workers=1, chunk_commands=CHUNK)
    assert not np.array_equal(other["kinematic"]["x"], alone["kinematic"]["x"])


def test_a_chunks_rows_are_that_chunk_played_alone():
    config = _config("physical")
    reference = play_references({"p": config}, SEED, COMMANDS, workers=1, chunk_commands=CHUNK)
    chunk = chunks_of("p", 3, COMMANDS, CHUNK)[5]  # ring 2's second chunk, played after five
    assert (chunk.ring, chunk.index) == (1, 1)
    start = chunk.ring * COMMANDS + chunk.index * CHUNK
    rows = reference["p"].iloc[start : start + chunk.commands].reset_index(drop=True)
    pd.testing.assert_frame_equal(rows, play_chunk(config, SEED, chunk))
    # Each placement's first goal toy is where it was placed, in the chunk's ring (0.5 to 0.75
    # m in the default world); the next ones may have been moved by the commands before.
    placed = rows.iloc[::3]
    assert np.hypot(placed["x"], placed["y"]).between(0.5, 0.75).all()


def _results(configs: dict[str, dict]) -> SimpleNamespace:
    """What `study_numbers` reads of a batch's results: each group's config and its tests."""
    rng = np.random.default_rng(0)
    tests = pd.concat(
        [
            pd.DataFrame(
                {
                    "group": group,
                    "trial": "t0",
                    "ring": rng.integers(1, 4, 30),
                    "x": rng.uniform(-0.7, 0.7, 30),
                    "y": rng.uniform(-0.7, 0.7, 30),
                    "error": rng.uniform(0.0, 1.0, 30),
                    "strategy": rng.choice(["hand", "tool", "vocal"], 30),
                }
            )
            for group in configs
        ],
        ignore_index=True,
    )
    return SimpleNamespace(configs=configs, study_tests=tests)


def test_a_kept_reference_is_read_back_without_playing(tmp_path, monkeypatch):
    unbuildable = _config("kinematic")
    unbuildable["trial"] = {**unbuildable["trial"], "grasp": "no-such-backend"}
    results = _results({"kinematic": _config("kinematic"), "broken": unbuildable})
    first = study_measure.study_numbers(results, 6, cache_dir=tmp_path, workers=1)
    assert list(first) == ["kinematic"]  # a group that makes no room is not measured
    assert first["kinematic"]["reference_commands_per_ring"] == 6
    assert len(list(tmp_path.glob("study-reference-*.parquet"))) == 1

    def played(*args, **kwargs):
        raise AssertionError("the kept reference should have been read back")

    monkeypatch.setattr(study_measure, "random_reference", played)
    kept = dict(results.configs)
    del kept["broken"]  # its reference is never kept: it would be tried again
    second = study_measure.study_numbers(_results(kept), 6, cache_dir=tmp_path, workers=2)
    assert json.dumps(second, sort_keys=True) == json.dumps(first, sort_keys=True)  # NaN too
