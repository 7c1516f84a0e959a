"""Evaluation scenes clear of the stick (docs/protocol.md D20): a named evaluation
setting, never the default. By default some ring-1 scenes of the evaluation's seed start with a
toy on the stick at its start pose, where the physical backend's learning placements never put
one; with `scenes_clear_of_stick` none does, and eval.json says so."""

from __future__ import annotations

import shutil

import numpy as np
import pytest

from experiments.cli.main import main
from experiments.measure.evaluation import (
    EvaluationSettings,
    competence_table,
    scene_placements,
)
from experiments.measure.trial_evaluation import evaluate_trial
from experiments.trial_dir import storage
from experiments.trial_dir.eval_record import SCENES_KEY, read_evaluation
from sim import Playroom
from sim.config import world_preset


def _on_the_stick(room: Playroom, scenes: np.ndarray) -> int:
    """How many scenes hold a toy nearer the stick at its start than its placements allow."""
    handle, tip = room.experimenter.start_stick()
    near = [any(not room.experimenter.clear_of_stick(t, handle, tip) for t in s) for s in scenes]
    return sum(near)


def _drawn_before(ring, n: int, rng: np.random.Generator, gap: float) -> np.ndarray:
    """The scenes as the evaluation drew them before the setting existed (its code then)."""
    out = np.empty((n, 3, 2))
    for p in range(n):
        for i in range(3):
            while True:
                radius, angle = rng.uniform(*ring), rng.uniform(0.0, 2 * np.pi)
                xy = radius * np.array([np.cos(angle), np.sin(angle)])
                if all(np.linalg.norm(xy - out[p, j]) >= gap for j in range(i)):
                    break
            out[p, i] = xy
    return out


def test_by_default_the_scenes_are_what_they_were_and_some_start_on_the_stick():
    room = Playroom("physical", seed=0, config=world_preset("study"))
    settings = EvaluationSettings()
    rng, old = np.random.default_rng(settings.seed), np.random.default_rng(settings.seed)
    for ring in room.config.toy_rings:
        scenes = scene_placements(room, ring, settings, rng)
        before = _drawn_before(ring, 100, old, room.min_toy_gap)
        np.testing.assert_array_equal(scenes, before)
        if ring == room.config.toy_rings[0]:
            assert _on_the_stick(room, scenes) > 0
        np.testing.assert_array_equal(rng.uniform(-1, 1, 2), old.uniform(-1, 1, 2))


def test_clear_scenes_change_only_the_scenes_that_were_on_the_stick():
    """A toy on the stick is drawn again from a generator of its own: every other scene, and
    every draw after (caregivers, the random reference's commands), is the default's."""
    room = Playroom("physical", seed=0, config=world_preset("study"))
    ring = room.config.toy_rings[0]
    default, clear = EvaluationSettings(), EvaluationSettings(scenes_clear_of_stick=True)
    rng_a, rng_b = np.random.default_rng(default.seed), np.random.default_rng(clear.seed)
    a = scene_placements(room, ring, default, rng_a)
    b = scene_placements(room, ring, clear, rng_b)
    changed = [p for p in range(len(a)) if not np.array_equal(a[p], b[p])]
    assert len(changed) == _on_the_stick(room, a) > 0
    np.testing.assert_array_equal(rng_a.uniform(-1, 1, 5), rng_b.uniform(-1, 1, 5))


def test_scenes_clear_of_the_stick_start_no_toy_on_it_in_any_ring():
    room = Playroom("physical", seed=0, config=world_preset("study"))
    settings = EvaluationSettings(scenes_clear_of_stick=True)
    rng = np.random.default_rng(settings.seed)
    for ring in room.config.toy_rings:
        scenes = scene_placements(room, ring, settings, rng)
        assert _on_the_stick(room, scenes) == 0
        apart = [np.linalg.norm(s[i] - s[j]) for s in scenes for i in range(3) for j in range(i)]
        assert min(apart) >= room.min_toy_gap


def test_the_scenes_of_the_competence_tests_are_the_settings_scenes():
    room = Playroom("kinematic", seed=0, config=world_preset("study"))
    settings = EvaluationSettings(n_placements=30, scenes_clear_of_stick=True)
    table = competence_table(_Resting(), room, settings)
    ring1 = table[table["ring"] == 1]
    scenes = ring1[["x", "y"]].to_numpy().reshape(-1, 3, 2)
    assert _on_the_stick(room, scenes) == 0


class _Resting:
    """An agent whose arm model is always nearer and whose command keeps the arm at rest."""

    def toy_models(self, toy: int) -> tuple[int, int]:
        return 2 + toy - 1, 6 + toy - 1

    def nearest_distance(self, model: int, context, goal) -> float:
        return 0.1 if model < 6 else 0.9

    def exploit(self, model: int, context, goal) -> np.ndarray:
        return np.zeros(21)


@pytest.mark.parametrize("clear", [False, True])
def test_eval_json_says_so_only_when_the_scenes_are_clear(tmp_path, trained_trial, clear):
    trial = tmp_path / "t"
    shutil.copytree(trained_trial.dir, trial)
    summary = evaluate_trial(trial, EvaluationSettings(n_placements=2, scenes_clear_of_stick=clear))
    assert (SCENES_KEY in summary) is clear
    flag = ["--scenes-clear-of-stick"] if clear else []
    assert main(["eval", str(trial), "--placements", "2", "--quiet", *flag]) == 0
    config = storage.read_json(trial / "config.json")
    assert read_evaluation(trial, config, "evaluate again").get(SCENES_KEY, False) is clear


def test_a_batch_whose_trials_were_tested_on_other_scenes_is_refused(tmp_path, batches):
    from experiments.analysis.results import ReportError, collect

    batch = tmp_path / "batch"
    shutil.copytree(batches["kinematic"], batch)
    first = sorted(p for p in batch.iterdir() if p.is_dir())[0]
    evaluate_trial(first, EvaluationSettings(n_placements=3, scenes_clear_of_stick=True))
    with pytest.raises(ReportError, match="--scenes-clear-of-stick"):
        collect(batch)
