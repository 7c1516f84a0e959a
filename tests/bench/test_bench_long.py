"""`playroom bench long`: one trial measured from the memory segments it writes, on a trial
short enough for the suite (the bench's own trial is 10^6 iterations)."""

from __future__ import annotations

import math

from experiments.bench.long import long_figures
from experiments.bench.names import ON_REQUEST, SECTION_NAMES


def test_a_long_trial_gives_its_costs_bytes_and_peak_memory_with_the_targets():
    figures = {name: (value, unit) for name, value, unit in long_figures(6000, 2000, 2000)}
    queries = {f"long_query_model{n}_{how}" for n in range(1, 11) for how in ("scan", "trees")}
    assert len(set(figures) & queries) >= 10  # at least 5 models hold rows by 6000 iterations
    assert set(figures) - queries == {
        "long_cost_per_iteration_near_2000",
        "long_cost_per_iteration_near_6000",
        "long_cost_ratio",
        "long_checkpoint_bytes_near_2000",
        "long_checkpoint_bytes_near_6000",
        "long_checkpoint_bytes_ratio",
        "long_peak_memory",
        "long_query_mean_scan",
        "long_query_mean_trees",
        "long_manifest_check",
        "long_manifest_checksums",
    }
    assert all(math.isfinite(v) and v > 0 for v, _ in figures.values())
    assert "target <= 2" in figures["long_cost_ratio"][1]
    assert "target <= 1.5" in figures["long_checkpoint_bytes_ratio"][1]
    assert "target < 1" in figures["long_manifest_checksums"][1]
    # A checkpoint writes about the same bytes early and late (its period's rows only).
    assert 0.5 < figures["long_checkpoint_bytes_ratio"][0] < 2
    late, early = (
        figures["long_cost_per_iteration_near_6000"],
        figures["long_cost_per_iteration_near_2000"],
    )
    ratio = late[0] / early[0]
    assert math.isclose(figures["long_cost_ratio"][0], ratio)
    assert 100 < figures["long_peak_memory"][0] < 4096  # MB: a Python process with MuJoCo


def test_the_long_section_runs_only_when_named():
    assert "long" in SECTION_NAMES and "long" in ON_REQUEST
