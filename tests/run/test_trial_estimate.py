"""A long trial states its expected time and disk before it starts, and a trial that will not
fit on its disk is refused, with one line, before anything is written, --quiet or not
(`--iterations 1000000000` started without a word; its checkpoints grew to 416 MB)."""

from __future__ import annotations

import shutil
from collections import namedtuple

import pytest

from experiments.cli.main import main
from experiments.run import estimate
from experiments.run.settings import TrialSettings
from experiments.run.trial import run_trial

Usage = namedtuple("Usage", "total used free")


def _free(monkeypatch, free: int) -> None:
    """The file systems of the test report `free` bytes free."""
    monkeypatch.setattr(shutil, "disk_usage", lambda path: Usage(10**15, 10**15 - free, free))


def test_disk_and_checkpoint_writes_grow_with_the_iterations_time_faster():
    one = estimate.trial_costs(TrialSettings(iterations=100000, checkpoint_every=1000))
    two = estimate.trial_costs(TrialSettings(iterations=200000, checkpoint_every=1000))
    assert two.disk_bytes == pytest.approx(2 * one.disk_bytes, rel=0.01)
    # Each row of memory is written once (experiments/trial_dir/memory_segments.py), not by every
    # checkpoint again.
    assert two.written_bytes == pytest.approx(2 * one.written_bytes, rel=0.01)
    assert two.seconds > 2 * one.seconds  # the query searches more rows as the memory grows
    slower = estimate.trial_costs(TrialSettings(grasp="physical", iterations=100000))
    assert slower.seconds > one.seconds and slower.disk_bytes == one.disk_bytes
    # A resumed trial costs what is left to run: nothing once it is finished.
    done = estimate.trial_costs(TrialSettings(iterations=100000), start=100000)
    assert done.seconds == 0 and done.written_bytes == 0


def test_the_estimated_growth_passes_through_the_measured_costs():
    """The learner's growth assumed by the estimate is the one `playroom bench long` measured:
    an iteration near 10^6 costs what it measured there, over one near 80000."""
    step = 1000
    near_a_million = estimate.growth_seconds(10**6) - estimate.growth_seconds(10**6 - step)
    per_iteration = estimate.SECONDS_NEAR_GROWTH_FROM + near_a_million / step
    assert per_iteration == pytest.approx(estimate.SECONDS_NEAR_A_MILLION, rel=0.01)
    assert estimate.growth_seconds(estimate.GROWTH_FROM) == 0.0


def test_a_trial_that_does_not_fit_on_its_disk_is_refused_before_anything_is_written(
    tmp_path, monkeypatch, capsys
):
    _free(monkeypatch, 10**6)  # 1 MB: less than 2000 iterations' logs and checkpoints
    out = tmp_path / "t"
    assert main(["run", "--out", str(out), "--iterations", "2000", "--quiet"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "free" in err[0] and str(tmp_path) in err[0], err
    assert not out.exists()


def test_the_issues_billion_iterations_are_refused_with_quiet(tmp_path, monkeypatch, capsys):
    _free(monkeypatch, 100 * 10**9)  # 100 GB
    out = tmp_path / "t"
    run = ["run", "--out", str(out), "--iterations", "1000000000", "--quiet"]
    assert main(run) == 2
    err = capsys.readouterr().err.strip().splitlines()
    # 740 GB: 740 B an iteration, the memory's rows written once (two checkpoints held them
    # all before: 1.36 TB).
    assert len(err) == 1 and "needs ~740 GB" in err[0] and "100 GB free" in err[0], err
    assert not out.exists()


def test_a_long_trial_states_its_time_and_disk_before_it_starts(tmp_path, monkeypatch):
    monkeypatch.setattr(estimate, "LONG_TRIAL", 150)
    notices: list[str] = []
    short = TrialSettings(iterations=150, checkpoint_every=50)
    run_trial(tmp_path / "short", short, progress=False, notify=notices.append)
    assert notices == []
    long = TrialSettings(iterations=200, checkpoint_every=50)
    run_trial(tmp_path / "long", long, progress=False, notify=notices.append)
    assert len(notices) == 1
    assert notices[0].startswith("this trial: ~") and "GB free" in notices[0]
    assert str(tmp_path / "long") in notices[0] and "in all" in notices[0]
