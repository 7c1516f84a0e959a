"""Trials compared whole: their newest checkpoints read with every model's rows (joined from the
memory segments they name, experiments/trial_dir/memory_segments.py), and their logs."""

from __future__ import annotations

from pathlib import Path

import numpy as np
from trial_logs import same_logs

from experiments.run.settings import TrialSettings
from experiments.trial_dir.layout import CHECKPOINT_FILE
from experiments.trial_dir.manifest import MANIFEST_KEY
from experiments.trial_dir.memory_segments import read_checkpoint

# A trial whose memory grows from its first iteration (the project preset learns from its
# bootstrap; the study's stores nothing before iteration 1000): 4 checkpoint periods.
SEGMENTED = TrialSettings(iterations=400, seed=3, checkpoint_every=100, preset="project")


# What a checkpoint records of its directory rather than of the trial's state: the name the
# trial was created as, and its manifest of files (whose bytes carry that name).
_OF_THE_DIRECTORY = ("trial_name", MANIFEST_KEY)


def same_state(a: Path, b: Path) -> None:
    """Same newest checkpoint, read whole (arrays, their types, metadata but what it records of
    its directory), same logs."""
    arrays_a, meta_a = read_checkpoint(Path(a) / CHECKPOINT_FILE)
    arrays_b, meta_b = read_checkpoint(Path(b) / CHECKPOINT_FILE)
    for key in _OF_THE_DIRECTORY:
        meta_a.pop(key, None), meta_b.pop(key, None)
    assert sorted(arrays_a) == sorted(arrays_b) and meta_a == meta_b
    for key in arrays_a:
        np.testing.assert_array_equal(arrays_a[key], arrays_b[key], err_msg=key)
        assert arrays_a[key].dtype == arrays_b[key].dtype, key
    same_logs(a, b)
