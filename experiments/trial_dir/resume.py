"""What a resume starts from: the newest usable checkpoint of a trial, restored, its logs
checked whole (checks.py) before anything is changed; then what a killed run left is put
right (a damaged newest checkpoint kept aside, the litter of killed writers removed, old logs
moved into their folders) and the work past the checkpoint dropped, which the run writes again.
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path
from typing import Generic

from experiments.trial_dir import manifest, memory_segments, storage
from experiments.trial_dir.checkpoint import A, Build, R, restore_newest
from experiments.trial_dir.checks import check_logs, listed_chunks
from experiments.trial_dir.errors import TrialError
from experiments.trial_dir.layout import (
    CHECKPOINT_FILE,
    DAMAGED_CHECKPOINT_FILE,
    LOG_KINDS,
    PREVIOUS_CHECKPOINT_FILE,
)
from experiments.trial_dir.old_logs import move_old_chunks
from experiments.trial_dir.storage import remove_litter


@dataclass
class Resumed(Generic[A, R]):
    """Where a resume starts: the agent and room restored from the newest usable checkpoint,
    its metadata, its manifest (None for a checkpoint from before manifests), the name the
    trial was created as, which every row of its logs carries, what its memory segments hold,
    and the data files its next checkpoint records (a trial from before manifests: every one it
    holds, as the resume checked them; else none yet)."""

    agent: A
    room: R
    meta: dict
    recorded: manifest.Manifest | None
    created_as: str
    memory: memory_segments.MemoryOnDisk
    unrecorded: list[Path]


def prepare_resume(
    trial_dir: Path,
    identity: dict,
    source: dict,
    parts: tuple[A, R],
    build: Build[A, R],
    notices: list[str],
) -> Resumed[A, R] | None:
    """What a resume starts from: the newest usable checkpoint of the trial of `identity`
    (config_file.trial_identity of the config.json it lies beside), restored into `parts`
    (fresh ones `build` builds where a restore fails half-way), whose logs are whole and as
    recorded, or None to start from iteration 0 (no checkpoint and no logs yet). The trial's
    chunks are listed once, after the checkpoint is restored, and everything is checked before
    anything is changed; then a damaged newest checkpoint is kept as checkpoint.damaged.npz,
    the litter of killed writers removed, old logs moved into their folders (their rows given
    the trial's `source` columns, config_file.source_of) and the work past the checkpoint (log
    chunks, memory segments, manifest files) dropped: the run writes it again. Appends to
    `notices` one line per thing done or noticed. TrialError if the trial cannot be resumed
    (the message says why and what can be done)."""
    newest = trial_dir / CHECKPOINT_FILE
    checkpointed = newest.exists() or (trial_dir / PREVIOUS_CHECKPOINT_FILE).exists()
    newest_usable = restore_newest(trial_dir, identity, parts, build) if checkpointed else None
    listed = listed_chunks(trial_dir)
    restored = None
    if newest_usable is None:
        # A run writes a checkpoint at iteration 0 before its first chunk (experiments/
        # run/trial.py): logs without one are a trial whose checkpoints were lost.
        chunks = [p for kind in LOG_KINDS for p in listed[kind].values()]
        if chunks:
            raise TrialError(
                f"{trial_dir} holds {len(chunks)} log chunk(s) but no checkpoint "
                f"({CHECKPOINT_FILE} and {PREVIOUS_CHECKPOINT_FILE} are missing): resuming "
                "would restart it from iteration 0 and delete its logs; refusing. Restore the "
                "checkpoints, or run the trial again from scratch into a new directory"
            )
        notices.append(f"{trial_dir} holds no checkpoint yet: starting it from iteration 0")
    else:
        agent, room, meta, recorded, fallback = newest_usable
        check_logs(trial_dir, int(meta["iteration"]), identity, recorded, listed)
        name = _created_as(meta, listed["iterations"], str(source["trial"]))
        restored = agent, room, meta, recorded, name
        if "identity" not in meta:
            notices.append(
                "the checkpoint predates trial identities (no seed or config hash in it): "
                "taken as this trial's; the next checkpoint carries one"
            )
        if fallback is not None:
            kept = ""
            if newest.exists():  # damaged, not missing: kept for whoever looks into it
                os.replace(newest, trial_dir / DAMAGED_CHECKPOINT_FILE)
                kept = f" (the damaged one is kept as {DAMAGED_CHECKPOINT_FILE})"
            notices.append(
                f"{fallback}; resumed from the previous checkpoint ({PREVIOUS_CHECKPOINT_FILE}), "
                f"at iteration {meta['iteration']}{kept}"
            )
    litter = remove_litter(trial_dir)
    if litter:
        notices.append(
            f"removed {len(litter)} temporary file(s) of a killed writer: {', '.join(litter)}"
        )
    moved, listed = move_old_chunks(trial_dir, source, listed)
    if moved:
        notices.append(
            f"moved {moved} log chunk(s) of the old layout (log/iterations-*.parquet, "
            "log/words-*.parquet) into log/iterations/ and log/words/"
        )
    # The work past the checkpoint (its log chunks, memory segments and manifest files), which
    # the run writes again.
    iteration = 0 if restored is None else int(restored[2]["iteration"])
    for by_start in listed.values():
        for start, path in by_start.items():
            if start >= iteration:
                path.unlink()
    memory_segments.drop_segments_past(trial_dir, iteration)
    manifest.drop_past(trial_dir, iteration)
    if restored is None:
        return None
    agent, room, meta, recorded, name = restored
    # A trial written before manifests: its next checkpoint records every data file it holds,
    # as checked above, and it is checked from then on.
    unrecorded = manifest.data_files(trial_dir) if meta.get(manifest.MANIFEST_KEY) is None else []
    return Resumed(agent, room, meta, recorded, name, memory_segments.on_disk(meta), unrecorded)


def _created_as(meta: dict, iterations: dict[int, Path], default: str) -> str:
    """The name a trial was created as, which every row of its logs carries however its
    directory is renamed or moved: its checkpoint's record of it, or for a checkpoint from
    before that record, the `trial` of its first log row (of the `iterations` chunks, by start;
    `default` where neither is)."""
    name = meta.get("trial_name")
    if isinstance(name, str):
        return name
    if iterations:
        try:
            rows = storage.read_table(next(iter(iterations.values())), ["trial"])
        except storage.CorruptFileError:
            return default  # the checks name the damage
        if "trial" in rows and len(rows):
            return str(rows["trial"].iloc[0])
    return default
