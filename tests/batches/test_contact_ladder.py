"""The contact ladder (experiments/batches/contact-ladder/): from the comparison's
kinematic trials (rung 0) to its physical ones (rung 5) and on to settling (rung 6), each rung
changes one rule of the rung before, so that the rungs' steps add up to the whole difference.
A rung is a batch config; rungs 0 and 5 are comparison-diva's own halves."""

from __future__ import annotations

import dataclasses
from pathlib import Path

from experiments.batches.spec import BatchSpec, load_spec
from experiments.run.trial_config import full_config
from experiments.trial_dir.config_file import config_differences
from sim.config import ACTS_ON, WorldConfig

ROOT = Path(__file__).resolve().parents[2]
LADDER = ROOT / "experiments" / "batches" / "contact-ladder"
ABLATIONS = ROOT / "experiments" / "batches" / "contact-ablations"
COMPARISON = "comparison-diva"
# What each rung changes from the one before (rung 3 changes the grasp rule: the backend).
CHANGES = {
    1: ["world.catch_rule"],
    2: ["world.arm_dynamics"],
    3: ["trial.grasp"],
    4: ["world.held_pose"],
    5: ["world.push_objects"],
    6: ["world.settle_between_movements"],
}


def _config(spec: BatchSpec) -> dict:
    """The config of the batch's first trial, less what tells the batch's trials apart."""
    (_, settings), *_ = spec.trials()
    config = full_config(settings)
    del config["trial"]["seed"], config["trial"]["overrides"]
    return config


def _rungs() -> dict[int, tuple[str, BatchSpec]]:
    comparison = load_spec(COMPARISON)
    rungs = {
        0: ("comparison-diva kinematic", dataclasses.replace(comparison, grasps=("kinematic",))),
        5: ("comparison-diva physical", dataclasses.replace(comparison, grasps=("physical",))),
    }
    for path in sorted(LADDER.glob("*.json")):
        rungs[int(path.name[:2])] = (path.name, load_spec(config_file=path))
    return rungs


def _acts_on(key: str) -> tuple[str, ...] | None:
    """The backends a world setting's rules read (None: every backend, or not a world one)."""
    section, name = key.split(".")
    fields = {f.name: f for f in dataclasses.fields(WorldConfig)}
    return fields[name].metadata.get(ACTS_ON) if section == "world" else None


def test_each_rung_changes_one_rule_of_the_rung_before(installed_generated_map):
    rungs = _rungs()
    assert sorted(rungs) == list(range(7))
    for _, spec in rungs.values():
        # The comparison's setting and first 32 seeds, one backend a rung.
        assert spec.preset == "study" and spec.voice == "diva" and spec.iterations == 80000
        assert spec.seeds == tuple(range(32)) or spec.seeds == tuple(range(64))
        assert len(spec.grasps) == 1
    for rung, expected in CHANGES.items():
        (before_name, before), (name, after) = rungs[rung - 1], rungs[rung]
        changes = config_differences(_config(before), _config(after))
        keys = [key for key, _, _ in changes]
        # A setting one backend alone reads stays or goes with that backend (a kinematic-only
        # setting would be refused on a physical trial): the step from the kinematic to the
        # physical room changes no rule but the backend's, its own switches holding the rest.
        if "trial.grasp" in keys:
            keys = [k for k in keys if k == "trial.grasp" or _acts_on(k) is None]
        assert keys == expected, f"{name} against {before_name}: {changes}"
        description = "" if rung == 5 else after.description
        assert rung == 5 or f"rung {rung} of 6" in description


def test_a_rung_that_is_a_contact_ablation_is_the_same_batch(installed_generated_map):
    """`make contact-ladder` runs such a rung into the ablation's directory: the same trials."""
    shared = 0
    for path in sorted(LADDER.glob("*.json")):
        ablation = ABLATIONS / f"{path.name[3:]}"
        if ablation.exists():
            assert load_spec(config_file=path) == load_spec(config_file=ablation)
            shared += 1
    assert shared == 2  # rungs 4 (no pushing) and 6 (settling)
