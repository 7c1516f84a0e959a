"""A checkpoint costs what changed since the one before it, not the trial's length (when
checkpoints that rewrote every row reached 416 MB by iteration 681000), and a trial whose
checkpoints hold every row themselves (written before memory segments) is still read,
evaluated, resumed and extended to the same trial."""

from __future__ import annotations

import dataclasses
import shutil
from pathlib import Path

from old_trials import as_before_manifests
from trial_states import SEGMENTED, same_state

from experiments.run.settings import TrialSettings
from experiments.run.trial import run_trial
from experiments.run.trial_parts import load_trial
from experiments.trial_dir import storage
from experiments.trial_dir.layout import CHECKPOINT_FILE, MEMORY_DIR, PREVIOUS_CHECKPOINT_FILE
from experiments.trial_dir.memory_segments import MEMORY_KEY, read_checkpoint


def test_a_late_checkpoint_writes_about_the_bytes_of_an_early_one(tmp_path, monkeypatch):
    written: list[tuple[str, int]] = []
    write_bytes = storage.write_bytes

    def recorded(path, data: bytes) -> None:
        written.append((Path(path).name, len(data)))
        write_bytes(path, data)

    monkeypatch.setattr(storage, "write_bytes", recorded)
    # The study's preset: no row is stored during its bootstrap (iterations 0 to 999).
    settings = TrialSettings(iterations=8000, seed=0, checkpoint_every=1000)
    run_trial(tmp_path / "t", settings, progress=False)
    # What each checkpoint wrote: the segment of its period's rows, then itself.
    per_checkpoint, pending = [], 0
    for name, size in written:
        if name.startswith("rows-"):
            pending += size
        elif name == CHECKPOINT_FILE:
            per_checkpoint.append(pending + size)
            pending = 0
    assert len(per_checkpoint) == 9  # at 0, 1000, ..., 8000
    at_2000, at_8000 = per_checkpoint[2], per_checkpoint[8]
    # Rewriting every row, the one at 8000 would write about 7 times the one at 2000.
    assert 0.8 < at_8000 / at_2000 < 1.25, per_checkpoint
    assert (tmp_path / "t" / CHECKPOINT_FILE).stat().st_size < 50_000


def _as_old_format(out: Path) -> None:
    """Turn a trial's checkpoints into what they were before memory segments: every row in the
    checkpoint's own arrays, no memory entry in its metadata, no memory/ folder."""
    as_before_manifests(out)  # segments came before manifests
    for name in (CHECKPOINT_FILE, PREVIOUS_CHECKPOINT_FILE):
        arrays, meta = read_checkpoint(out / name)
        del meta[MEMORY_KEY]
        storage.write_arrays(out / name, arrays, meta)
    shutil.rmtree(out / MEMORY_DIR)


def test_an_old_trial_is_evaluated_resumed_and_extended_to_the_same_trial(
    segmented_trial, tmp_path
):
    out = tmp_path / "old"
    run_trial(out, dataclasses.replace(SEGMENTED, iterations=200), progress=False)
    new = read_checkpoint(out / CHECKPOINT_FILE)[0]
    _as_old_format(out)
    _, agent, _, meta = load_trial(out)  # what an evaluation reads
    assert meta["iteration"] == 200
    assert sum(agent.memory_sizes().values()) == sum(
        len(v) for k, v in new.items() if k.endswith(".motor")
    )
    # Extended by one period: the first new checkpoint writes every row once, as a segment.
    run_trial(out, dataclasses.replace(SEGMENTED, iterations=300), resume=True, progress=False)
    segment, segment_meta = storage.read_arrays(out / MEMORY_DIR / "rows-00000200.npz")
    assert set(segment_meta["first_rows"].values()) == {0}
    assert MEMORY_KEY not in storage.read_meta(out / PREVIOUS_CHECKPOINT_FILE)
    # Its newest checkpoint lost: the resume falls back to the old one, and redoes the period.
    (out / CHECKPOINT_FILE).write_bytes(b"damaged")
    notices: list[str] = []
    run_trial(out, SEGMENTED, resume=True, progress=False, notify=notices.append)
    assert any("previous checkpoint" in n and "iteration 200" in n for n in notices)
    same_state(out, segmented_trial)
