"""The contact step unbundled and the contact factorial: batch configs each of whose
rungs or cells changes one rule (experiments/batches/contact-unbundled/, held-pose-returns/,
contact-factorial/), every one the comparison's setting, every agent tested in both worlds."""

from __future__ import annotations

from pathlib import Path

from test_contact_ladder import _acts_on, _config, _rungs

from experiments.batches.spec import BatchSpec, load_spec
from experiments.trial_dir.config_file import config_differences

BATCHES = Path(__file__).resolve().parents[2] / "experiments" / "batches"


def _spec(folder: str, name: str) -> BatchSpec:
    return load_spec(config_file=BATCHES / folder / f"{name}.json")


def _changes(before: BatchSpec, after: BatchSpec) -> list[str]:
    """The settings one batch changes from another; across backends, the backend and the
    settings both read (each backend's own switches stay or go with it)."""
    keys = [key for key, _, _ in config_differences(_config(before), _config(after))]
    if "trial.grasp" in keys:
        keys = [k for k in keys if k == "trial.grasp" or _acts_on(k) is None]
    return keys


def _common(spec: BatchSpec, seeds: int) -> None:
    assert spec.preset == "study" and spec.voice == "diva" and spec.iterations == 80000
    assert spec.seeds == tuple(range(seeds)) and len(spec.grasps) == 1
    assert set(spec.eval_worlds) == {"kinematic", "physical"}


def test_each_rung_of_the_unbundled_contact_step_changes_one_rule(installed_generated_map):
    """servo-arm -> clear placements -> the contact's reach alone -> obstruction ->
    contact-aligned (the caregiver's carrying welded): the ladder's contact step in four."""
    ladder = {n: spec for n, (_, spec) in _rungs().items()}
    steps = [
        (ladder[2], _spec("contact-unbundled", "01-clear-placements"), ["world.placements_clear"]),
        (
            _spec("contact-unbundled", "01-clear-placements"),
            _spec("contact-unbundled", "02-contact-reach"),
            ["trial.grasp"],
        ),
        (
            _spec("contact-unbundled", "02-contact-reach"),
            _spec("contact-unbundled", "03-obstruction"),
            ["world.unheld_contacts"],
        ),
        (_spec("contact-unbundled", "03-obstruction"), ladder[3], ["world.caregiver_carrying"]),
    ]
    for before, after, expected in steps:
        _common(after, 32)
        assert _changes(before, after) == expected, after.description


def test_the_held_pose_step_with_equal_returns_changes_the_pose_alone(installed_generated_map):
    ladder = {n: spec for n, (_, spec) in _rungs().items()}
    aligned, touch = _spec("held-pose-returns", "aligned"), _spec("held-pose-returns", "touch")
    _common(aligned, 32)
    _common(touch, 32)
    assert _changes(aligned, touch) == ["world.held_pose"]
    assert _changes(ladder[3], aligned) == ["world.stick_return_reach"]
    assert _changes(ladder[4], touch) == ["world.stick_return_reach"]


def test_each_factorial_cell_completes_a_two_by_two_of_one_rule_each(installed_generated_map):
    """Each square: (low, low), (high, low), (low, high), (high, high) of two rules, each edge
    one rule: the ladder's rungs and the comparison's halves, and the cells it lacks."""
    ladder = {n: spec for n, (_, spec) in _rungs().items()}

    def cell(name: str) -> BatchSpec:
        return _spec("contact-factorial", name)

    squares = {
        ("world.held_pose", "world.push_objects"): (
            ladder[3],
            ladder[4],
            cell("aligned-push"),
            ladder[5],
        ),
        ("world.catch_rule", "world.arm_dynamics"): (
            ladder[0],
            ladder[1],
            cell("study-catch-servo"),
            ladder[2],
        ),
        ("world.catch_rule", "world.catch_distance"): (
            ladder[0],
            ladder[1],
            cell("study-catch-near"),
            cell("held-catch-near"),
        ),
    }
    for (a, b), (low_low, high_low, low_high, high_high) in squares.items():
        assert _changes(low_low, high_low) == [a] and _changes(low_high, high_high) == [a]
        assert _changes(low_low, low_high) == [b] and _changes(high_low, high_high) == [b]
    for name in ("aligned-push", "study-catch-servo", "study-catch-near", "held-catch-near"):
        _common(cell(name), 16)
