"""The grasp rate of the stick against where it lies (experiments/analysis/curves.py
`grasp_rate_by_distance`, `falling_rate_distance`; experiments/report/stick_reach.py), on
hand-made logs."""

from __future__ import annotations

import math

import numpy as np
import pandas as pd
import pytest

from experiments.analysis.curves import falling_rate_distance, grasp_rate_by_distance
from experiments.report import stick_reach
from experiments.trial_dir import storage
from experiments.trial_dir.layout import BACKEND_FILE, CONFIG_FILE, LOG_DIR


def _log(rows: list[tuple[str, float, bool]]) -> pd.DataFrame:
    """An iterations log of (motor space, handle distance, stick grasped) rows."""
    space, distance, grasped = zip(*rows, strict=True)
    return pd.DataFrame(
        {"motor_space": space, "stick_distance": distance, "stick_grasped": grasped}
    )


def _many(space: str, distance: float, n: int, grasps: int) -> list[tuple[str, float, bool]]:
    return [(space, distance, k < grasps) for k in range(n)]


def test_movements_are_counted_per_distance_bin_arm_only():
    log = _log(
        _many("arm", 0.253, 10, 3)
        + _many("arm", 0.257, 10, 1)  # the same 1 cm bin as 0.253
        + _many("arm", 0.535, 5, 0)
        + _many("voice", 0.535, 7, 7)  # no vocal movement reaches: left out
    )
    table = grasp_rate_by_distance(log)
    assert table[["iterations", "grasps"]].values.tolist() == [[20, 4], [5, 0]]
    assert table["rate"].tolist() == pytest.approx([0.2, 0.0])
    assert table["low"].tolist() == pytest.approx([0.25, 0.53])
    assert table["high"].tolist() == pytest.approx([0.26, 0.54])
    wide = grasp_rate_by_distance(log, bin_width=0.5)
    assert wide[["low", "iterations", "grasps"]].values.tolist() == [[0.0, 20, 4], [0.5, 5, 0]]
    with pytest.raises(ValueError, match="bin_width"):
        grasp_rate_by_distance(log, bin_width=0.0)


def _rates() -> pd.DataFrame:
    """Start bin 20%; 0.40 m 30%; 0.51 m 12% (above half); 0.52 m only 50 movements at 0%
    (too few to decide); 0.53 m 8% (below half); 0.54 m 1%."""
    rows = (
        _many("arm", 0.251, 200, 40)
        + _many("arm", 0.401, 200, 60)
        + _many("arm", 0.511, 200, 24)
        + _many("arm", 0.521, 50, 0)
        + _many("arm", 0.531, 200, 16)
        + _many("arm", 0.541, 200, 2)
    )
    return grasp_rate_by_distance(_log(rows))


def test_the_falling_distance_is_the_first_large_bin_below_the_fraction():
    rates = _rates()
    assert falling_rate_distance(rates, start=0.25) == pytest.approx(0.53)
    assert falling_rate_distance(rates, start=0.25, min_iterations=50) == pytest.approx(0.52)
    assert falling_rate_distance(rates, start=0.25, fraction=0.7) == pytest.approx(0.51)
    assert falling_rate_distance(rates, start=0.25, fraction=0.1) == pytest.approx(0.54)
    assert math.isnan(falling_rate_distance(rates, start=0.25, fraction=0.01))
    assert math.isnan(falling_rate_distance(rates, start=0.30))  # no bin holds the start


def test_the_command_draws_the_figure_and_prints_the_table(tmp_path, capsys):
    batch = tmp_path / "batch"
    world = {"segment_lengths": [0.25, 0.15, 0.1], "grasp_distance": 0.1}
    world |= {"stick_start_handle": [-0.25, 0.0]}
    rng = np.random.default_rng(0)
    for grasp in ("kinematic", "physical"):
        trial = batch / f"{grasp}-random-seed0000"
        (trial / LOG_DIR).mkdir(parents=True)
        storage.write_json(
            trial / CONFIG_FILE, {"trial": {"grasp": grasp, "seed": 0}, "world": world}
        )
        log = _log(
            [("arm", d, bool(rng.random() < 0.2)) for d in rng.uniform(0.25, 0.26, 200)]
            + _many("arm", 0.535, 200, 2 if grasp == "physical" else 40)
        )
        storage.write_table(trial / LOG_DIR / "iterations-00000000.parquet", log)
    out = tmp_path / "figure.png"
    assert stick_reach.main([str(batch), "--out", str(out)]) == 0
    assert out.read_bytes().startswith(b"\x89PNG")
    printed = capsys.readouterr().out
    assert "| 0.53-0.54 | 200 | 20.0% | 200 | 1.0% |" in printed
    assert "proposed physical return reach: 0.53 m" in printed


def test_each_backend_is_drawn_at_the_reach_its_trials_recorded(tmp_path):
    """Any backends, none known by name: a trial's backend.json gives its reach; a trial
    written before the record, its config (experiments/trial_dir/backend_record.py)."""
    batch = tmp_path / "batch"
    world = {"segment_lengths": [0.25, 0.15, 0.1], "grasp_distance": 0.1}
    world |= {"stick_start_handle": [-0.25, 0.0]}
    recorded = {"grasp": "magnetic", "reach": 0.8, "solid": False, "pushes": False}
    recorded["closed_form"] = False
    for grasp, record in (("kinematic", None), ("magnetic", recorded)):
        trial = batch / f"{grasp}-random-seed0000"
        (trial / LOG_DIR).mkdir(parents=True)
        config = {"trial": {"grasp": grasp, "seed": 0}, "world": world}
        storage.write_json(trial / CONFIG_FILE, config)
        if record is not None:
            storage.write_json(trial / BACKEND_FILE, record)
        log = _log(_many("arm", 0.251, 200, 40) + _many("arm", 0.535, 200, 40))
        storage.write_table(trial / LOG_DIR / "iterations-00000000.parquet", log)
    lines = stick_reach.distance_lines(stick_reach.batch_rates(batch))
    reaches = {label.split(":")[0]: x for x, _, style, label in lines if style == "--"}
    assert reaches == {"kinematic": pytest.approx(0.6), "magnetic": 0.8}
