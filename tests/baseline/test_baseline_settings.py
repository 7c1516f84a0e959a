"""The RL baseline's settings and command line, without its library: how movements are shared,
what a batch config gives it, and the refusals said in one line before any work."""

from __future__ import annotations

import sys
from pathlib import Path

import pytest

from experiments.baseline.many import batch_baselines
from experiments.baseline.settings import BaselineError, BaselineSettings, summary_config
from experiments.baseline.training import rl_library
from experiments.cli.main import main

ROOT = Path(__file__).resolve().parents[2]
COMPARISON = ROOT / "experiments" / "batches" / "rl-baseline" / "comparison.json"


@pytest.mark.parametrize("steps", [3, 300, 20000, 20001, 20002])
def test_the_movements_are_shared_over_the_toys_and_add_up(steps):
    shares = BaselineSettings(steps=steps).toy_steps()
    assert sorted(shares) == [1, 2, 3] and sum(shares.values()) == steps
    assert max(shares.values()) - min(shares.values()) <= 1


def test_each_toy_explores_from_its_own_seed_and_a_run_is_summarised_as_a_trial():
    settings = BaselineSettings(steps=300, seed=4, grasp="physical")
    seeds = [settings.toy_seed(t) for t in (1, 2, 3)]
    assert len(set(seeds)) == 3 and seeds == [settings.toy_seed(t) for t in (1, 2, 3)]
    assert BaselineSettings(steps=300, seed=5).toy_seed(1) != seeds[0]
    trial = summary_config(settings)["trial"]
    assert trial == {"grasp": "physical", "seed": 4, "babbling": "sac-her", "iterations": 300}


@pytest.mark.parametrize(
    "given, message",
    [
        ({"steps": 2}, "steps must be an integer >= 3"),
        ({"steps": 300, "grasp": "magnetic"}, "unknown grasp 'magnetic'"),
        ({"steps": 300, "eval_placements": 0}, "eval_placements must be an integer >= 1"),
        ({"steps": 300, "seed": -1}, "seed must be a non-negative integer"),
    ],
)
def test_bad_settings_are_refused_in_one_line(given, message):
    with pytest.raises(BaselineError, match=message) as caught:
        BaselineSettings(**given)
    assert "\n" not in str(caught.value)


def test_the_comparison_config_gives_both_learners_the_same_movements_seeds_and_tests():
    runs = batch_baselines(COMPARISON)
    assert {r.grasp for r in runs} == {"kinematic", "physical"}
    for grasp in ("kinematic", "physical"):
        seeds = sorted(r.seed for r in runs if r.grasp == grasp)
        assert len(seeds) >= 8 and seeds == list(range(len(seeds)))
    assert all(r.steps >= 20000 and r.eval_placements == 100 for r in runs)
    assert {r.preset for r in runs} == {"study"}


def test_the_command_refuses_in_one_line_before_any_work(tmp_path, capsys):
    out = tmp_path / "run"
    assert main(["rl-baseline", "--out", str(out)]) == 2
    assert main(["rl-baseline", "--config", str(COMPARISON), "--seed", "3", "--out", str(out)]) == 2
    assert main(["rl-baseline", "--steps", "30", "--workers", "2", "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 3 and all(line.startswith("playroom rl-baseline: error:") for line in err)
    assert "--steps N is required" in err[0] and "--seed" in err[1] and "--workers" in err[2]
    assert not out.exists()


def test_without_the_rl_extra_the_baseline_names_it(monkeypatch):
    monkeypatch.setitem(sys.modules, "stable_baselines3", None)  # an import of it fails
    with pytest.raises(BaselineError, match=r"make install-rl") as caught:
        rl_library()
    assert "\n" not in str(caught.value)
