"""The memory's rows are written once, in append-only segments
(experiments/trial_dir/memory_segments.py), and a trial still resumes bit for bit from a kill at
every moment of a checkpoint period; a segment that is stray, missing, damaged or another trial's is
ignored, or named and fallen back from as a damaged checkpoint is."""

from __future__ import annotations

import dataclasses
import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest
from trial_states import SEGMENTED, same_state

from experiments.batches.runner import is_complete
from experiments.run.trial import run_trial
from experiments.run.trial_parts import load_trial
from experiments.trial_dir import storage
from experiments.trial_dir.errors import TrialError
from experiments.trial_dir.layout import (
    CHECKPOINT_FILE,
    DAMAGED_CHECKPOINT_FILE,
    LOCK_FILE,
    MEMORY_DIR,
    PREVIOUS_CHECKPOINT_FILE,
)
from experiments.trial_dir.memory_segments import MEMORY_KEY, read_checkpoint

TOTAL, PERIOD = SEGMENTED.iterations, SEGMENTED.checkpoint_every
SEGMENTS = [f"rows-{start:08d}.npz" for start in range(0, TOTAL, PERIOD)]


def _copy(trial: Path, tmp_path: Path) -> Path:
    out = tmp_path / "trial"
    shutil.copytree(trial, out)
    return out


def _memory(out: Path) -> dict[str, bytes]:
    return {p.name: p.read_bytes() for p in sorted((out / MEMORY_DIR).iterdir())}


def _contents(out: Path) -> dict:
    return {p: p.read_bytes() for p in out.rglob("*") if p.is_file() and p.name != LOCK_FILE}


def _dead_pid() -> int:
    proc = subprocess.Popen([sys.executable, "-c", "pass"])
    proc.wait()
    return proc.pid


class _Killed(BaseException):
    """The run stops where this is raised, as under SIGKILL: nothing of the trial catches it,
    and a file being written is left as its temporary."""


def _run_killed(monkeypatch, out: Path, target: str, occurrence: int) -> None:
    """Run SEGMENTED' trial into `out`, killed just before the `occurrence`-th rename onto
    `target` (relative to `out`): every file lands by a rename (storage.write_bytes), and so
    does the newest checkpoint onto the previous one's name. The killed writer's temporary
    files are left as a dead process's."""
    real, seen = os.replace, []

    def replace(src, dst, *args, **kwargs):
        if Path(dst) == out / target:
            seen.append(dst)
            if len(seen) == occurrence:
                raise _Killed
        return real(src, dst, *args, **kwargs)

    with monkeypatch.context() as patch:
        patch.setattr(os, "replace", replace)
        with pytest.raises(_Killed):
            run_trial(out, SEGMENTED, progress=False)
    dead = _dead_pid()
    for tmp in out.rglob(f".*.{os.getpid()}.tmp"):
        tmp.rename(tmp.with_name(tmp.name.replace(f".{os.getpid()}.", f".{dead}.")))


def test_each_row_is_written_once_and_the_checkpoint_names_the_newest_segment(segmented_trial):
    assert sorted(_memory(segmented_trial)) == SEGMENTS
    arrays, meta = storage.read_arrays(segmented_trial / CHECKPOINT_FILE)
    assert meta[MEMORY_KEY]["newest"] == SEGMENTS[-1]
    # The checkpoint holds no row of its own: they all lie in the segments.
    assert all(len(v) == 0 for k, v in arrays.items() if k.endswith((".motor", ".key")))
    rows = meta[MEMORY_KEY]["segment_rows"]
    rows_of, _ = read_checkpoint(segmented_trial / CHECKPOINT_FILE)
    assert sum(rows.values()) > TOTAL / 2
    for number, count in rows.items():
        assert len(rows_of[f"agent/model{number}.motor"]) == count
    _, segment_meta = storage.read_arrays(segmented_trial / MEMORY_DIR / SEGMENTS[1])
    assert segment_meta["identity"] == meta["identity"]
    assert segment_meta["iterations"] == [PERIOD, 2 * PERIOD]
    assert segment_meta["previous"] == SEGMENTS[0]


# Killed at every moment of the checkpoint period from 200 to 300: before each file lands (the
# file half-written: its temporary is left), its log chunks, its segment, the checkpoint at 200
# moved aside (the 3rd moved, after those at 0 and 100), the one at 300 (the 4th written).
KILL_POINTS = {
    "before its iterations log chunk": ("log/iterations/chunk-00000200.parquet", 1),
    "before its words log chunk": ("log/words/chunk-00000200.parquet", 1),
    "before its segment": (f"{MEMORY_DIR}/rows-00000200.npz", 1),
    "between its segment and its checkpoint": (PREVIOUS_CHECKPOINT_FILE, 3),
    "after the previous checkpoint moved aside": (CHECKPOINT_FILE, 4),
}


@pytest.mark.parametrize("moment", KILL_POINTS, ids=list(KILL_POINTS))
def test_a_run_killed_at_any_moment_resumes_bit_for_bit(
    segmented_trial, tmp_path, monkeypatch, moment
):
    out = tmp_path / "killed"
    _run_killed(monkeypatch, out, *KILL_POINTS[moment])
    run_trial(out, SEGMENTED, resume=True, progress=False)
    same_state(out, segmented_trial)
    assert _memory(out) == _memory(segmented_trial)  # the same segments, byte for byte
    assert not list(out.rglob("*.tmp"))


def test_a_stray_segment_beyond_the_newest_checkpoint_is_ignored_then_written_again(
    segmented_trial, tmp_path, monkeypatch
):
    out = tmp_path / "killed"
    _run_killed(monkeypatch, out, *KILL_POINTS["between its segment and its checkpoint"])
    stray = out / MEMORY_DIR / "rows-00000200.npz"
    assert stray.exists() and load_trial(out)[3]["iteration"] == 200
    stray.write_bytes(b"not the run's")  # whatever it holds: nothing names it
    assert load_trial(out)[3]["iteration"] == 200
    run_trial(out, SEGMENTED, resume=True, progress=False)
    same_state(out, segmented_trial)
    assert stray.read_bytes() == (segmented_trial / MEMORY_DIR / stray.name).read_bytes()


def _truncate(path: Path) -> None:
    path.write_bytes(path.read_bytes()[:300])


SEGMENT_DAMAGE = {
    "damaged": ("is damaged or truncated", _truncate),
    "missing": ("is missing", lambda path: path.unlink()),
}


@pytest.mark.parametrize("damage", SEGMENT_DAMAGE, ids=list(SEGMENT_DAMAGE))
def test_a_lost_newest_segment_is_named_and_the_resume_falls_back(
    segmented_trial, tmp_path, damage
):
    problem, hurt = SEGMENT_DAMAGE[damage]
    out = _copy(segmented_trial, tmp_path)
    segment = out / MEMORY_DIR / SEGMENTS[-1]  # named by the newest checkpoint only
    hurt(segment)
    assert not is_complete(out)  # a batch rerun runs it again
    with pytest.raises(TrialError, match="--resume") as exc:
        load_trial(out)  # an evaluation does not guess
    assert f"{segment} {problem}" in str(exc.value) and CHECKPOINT_FILE in str(exc.value)
    newest = (out / CHECKPOINT_FILE).read_bytes()
    notices: list[str] = []
    run_trial(out, SEGMENTED, resume=True, progress=False, notify=notices.append)
    fallback = [n for n in notices if "previous checkpoint" in n]
    assert len(fallback) == 1 and str(segment) in fallback[0] and "iteration 300" in fallback[0]
    assert (out / DAMAGED_CHECKPOINT_FILE).read_bytes() == newest
    same_state(out, segmented_trial)
    assert _memory(out) == _memory(segmented_trial)


def test_a_segment_both_checkpoints_need_stops_with_one_line_and_changes_nothing(
    segmented_trial, tmp_path
):
    out = _copy(segmented_trial, tmp_path)
    segment = out / MEMORY_DIR / SEGMENTS[1]
    _truncate(segment)
    before = _contents(out)
    for reader in (lambda: load_trial(out), lambda: run_trial(out, SEGMENTED, resume=True)):
        with pytest.raises(TrialError, match="cannot be restored") as exc:
            reader()
        line = str(exc.value)
        assert "\n" not in line and line.count(str(segment)) == 2 and "from scratch" in line
    assert _contents(out) == before


def test_a_segment_of_another_trial_is_refused(segmented_trial, tmp_path):
    other = tmp_path / "other"
    run_trial(other, dataclasses.replace(SEGMENTED, seed=SEGMENTED.seed + 1), progress=False)
    out = _copy(segmented_trial, tmp_path)
    shutil.copy(other / MEMORY_DIR / SEGMENTS[-1], out / MEMORY_DIR / SEGMENTS[-1])
    before = _contents(out)
    with pytest.raises(TrialError, match="belongs to another trial"):
        run_trial(out, SEGMENTED, resume=True, progress=False)
    assert not is_complete(out)
    assert _contents(out) == before
