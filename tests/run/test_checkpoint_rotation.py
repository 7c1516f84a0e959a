"""A trial always has a whole checkpoint.npz: while a new checkpoint is written, the one before
it stays in place (and is kept as checkpoint.prev.npz), so a reader, or a writer killed at that
moment, never finds the trial without its newest checkpoint."""

from __future__ import annotations

import os

from experiments.run.settings import TrialSettings
from experiments.run.trial import run_trial
from experiments.trial_dir import storage
from experiments.trial_dir.layout import CHECKPOINT_FILE, PREVIOUS_CHECKPOINT_FILE

SETTINGS = TrialSettings(grasp="kinematic", iterations=60, checkpoint_every=20, seed=3)


def test_the_newest_checkpoint_is_in_place_while_the_next_is_written(tmp_path, monkeypatch):
    out = tmp_path / "trial"
    seen: list[int | None] = []
    write_arrays = storage.write_arrays

    def writing(path, arrays, meta):
        if path.name == CHECKPOINT_FILE:  # what a reader finds at this moment
            try:
                seen.append(storage.read_meta(path)["iteration"])
            except storage.CorruptFileError:  # missing, or not whole
                seen.append(None)
        write_arrays(path, arrays, meta)

    monkeypatch.setattr(storage, "write_arrays", writing)
    run_trial(out, SETTINGS, progress=False)
    # The first checkpoint (at 0) has none before it; each later one finds the one before it.
    assert seen == [None, 0, 20, 40], seen
    assert storage.read_meta(out / PREVIOUS_CHECKPOINT_FILE)["iteration"] == 40
    assert storage.read_meta(out / CHECKPOINT_FILE)["iteration"] == 60


def test_without_hard_links_the_previous_checkpoint_is_a_copy(tmp_path, monkeypatch):
    def no_links(*args, **kwargs):
        raise PermissionError(1, "Operation not permitted")

    monkeypatch.setattr(os, "link", no_links)
    out = tmp_path / "trial"
    run_trial(out, SETTINGS, progress=False)
    assert storage.read_meta(out / PREVIOUS_CHECKPOINT_FILE)["iteration"] == 40
    assert not [p.name for p in out.iterdir() if p.name.endswith(".tmp")]
