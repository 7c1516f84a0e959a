"""Faults of the machine, not of the request: a full disk and read-only places end a command
with one line and exit code 1 or 2 (experiments/cli/faults.py), leave nothing half-written,
and leave a trial resumable; reports never write into the batches they read."""

from __future__ import annotations

import builtins
import errno
import io
import os
import shutil
from pathlib import Path

import pytest
from old_trials import before_manifests
from trial_logs import same_logs

from experiments.analysis.results import ReportError
from experiments.cli.main import main
from experiments.measure import study_measure
from experiments.measure.for_reports import room_measures
from experiments.report.batch_report import write_report
from experiments.report.figures import FigureFile
from experiments.run.settings import TrialSettings
from experiments.run.trial import run_trial
from experiments.trial_dir import storage
from experiments.trial_dir.layout import CHECKPOINT_FILE, CONFIG_FILE, LOCK_FILE
from experiments.trial_dir.memory_segments import read_checkpoint

PNG = b"\x89PNG\r\n\x1a\n"


class _FullFile:
    """A file opened on a full disk: it exists, and every write fails."""

    def __init__(self, f) -> None:
        self._f = f

    def __enter__(self) -> _FullFile:
        return self

    def __exit__(self, *exc) -> None:
        self._f.close()

    def write(self, data: bytes) -> int:
        raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))

    def __getattr__(self, name: str):
        return getattr(self._f, name)


class FullDisk:
    """`open` for experiments.storage: under `root`, the disk is full after `allowed` files
    were written (files are still created, as on a full disk, and writes then fail)."""

    def __init__(self, root: Path, allowed: int) -> None:
        self.root, self.allowed, self.written = Path(root).resolve(), allowed, 0

    def __call__(self, path, mode: str = "r", *args, **kwargs):
        f = builtins.open(path, mode, *args, **kwargs)
        if "w" not in mode or not Path(path).resolve().is_relative_to(self.root):
            return f
        self.written += 1
        return f if self.written <= self.allowed else _FullFile(f)


def _files(directory: Path) -> dict[str, bytes]:
    """Every file under `directory` (the lock file names its last holder: not data)."""
    found = directory.rglob("*") if directory.exists() else []
    return {
        str(p.relative_to(directory)): p.read_bytes()
        for p in found
        if p.is_file() and p.name != LOCK_FILE
    }


def _one_line(err: str, *words: str) -> str:
    lines = err.strip().splitlines()
    assert len(lines) == 1, err
    for word in words:
        assert word in lines[0], lines[0]
    return lines[0]


def _copy_batch(batch: Path, target: Path) -> Path:
    shutil.copytree(batch, target)
    return target


# A full disk ----------------------------------------------------------------------------------
RUN = ["run", "--iterations", "150", "--seed", "3", "--checkpoint-every", "30", "--quiet"]


def test_disk_full_during_a_run_is_one_line_and_it_resumes_to_the_same_trial(
    tmp_path, monkeypatch, capsys
):
    whole = tmp_path / "whole"
    run_trial(whole, TrialSettings(iterations=150, seed=3, checkpoint_every=30), progress=False)
    out = tmp_path / "full"
    # config, log/README.txt, provenance, the backend's record, the manifest and checkpoint at
    # iteration 0, then a log chunk, a manifest and a checkpoint per 30 iterations: full while
    # writing the checkpoint at 90 (after the one at 60 was moved aside as the previous one).
    monkeypatch.setattr(storage, "open", FullDisk(out, allowed=14), raising=False)
    assert main([*RUN, "--out", str(out)]) == 1
    line = _one_line(capsys.readouterr().err, "no space left on device", "--resume")
    assert f"cannot write {out / CHECKPOINT_FILE}" in line
    assert "iteration 60" in line  # what is kept: the previous checkpoint
    assert not list(out.rglob("*.tmp"))
    monkeypatch.undo()
    assert main([*RUN, "--out", str(out), "--resume"]) == 0
    same_logs(out, whole)
    # Whole: the checkpoint's own arrays and every model's rows from its memory segments.
    arrays_a, meta_a = read_checkpoint(out / CHECKPOINT_FILE)
    arrays_b, meta_b = read_checkpoint(whole / CHECKPOINT_FILE)
    # What each records of its own directory (its name, its files) aside.
    assert before_manifests(meta_a) == before_manifests(meta_b)
    assert sorted(arrays_a) == sorted(arrays_b)
    for key in arrays_a:
        assert (arrays_a[key] == arrays_b[key]).all(), key


def test_disk_full_at_a_new_trials_first_file_leaves_its_folder_reusable(
    tmp_path, monkeypatch, capsys
):
    out = tmp_path / "t"
    args = [*RUN[:2], "40", *RUN[3:], "--out", str(out)]
    monkeypatch.setattr(storage, "open", FullDisk(out, allowed=0), raising=False)
    assert main(args) == 1
    _one_line(capsys.readouterr().err, f"cannot write {out / CONFIG_FILE}", "start it again")
    assert _files(out) == {}  # nothing but the lock: the same command may start it again
    monkeypatch.undo()
    assert main(args) == 0


def test_disk_full_during_eval_leaves_the_evaluation_as_it_was(
    batches, tmp_path, monkeypatch, capsys
):
    trial = _copy_batch(batches["kinematic"], tmp_path / "batch") / "kinematic-random-seed0000"
    before = _files(trial)
    monkeypatch.setattr(storage, "open", FullDisk(trial, allowed=2), raising=False)
    assert main(["eval", str(trial), "--placements", "1", "--quiet"]) == 1
    _one_line(capsys.readouterr().err, "no space left on device", "as they were")
    # Not the new competence table beside the old eval.json: all old, nothing left over.
    assert _files(trial) == before


@pytest.fixture
def light_figures(monkeypatch):
    """Reports draw two tiny figures instead of their real ones (tests/report/test_report.py checks
    those): what is checked here is how the files are written. Both pages draw them through
    `batch_report.numbers_and_figures`."""
    from experiments.report import batch_report

    def figures(*args, **kwargs):
        return [
            FigureFile(f"fig{i}.png", "a figure", "its caption", PNG + bytes(i)) for i in (1, 2)
        ]

    monkeypatch.setattr(batch_report, "report_figures", figures)
    monkeypatch.setattr(batch_report, "study_figure_files", lambda *args: [])


def test_disk_full_during_a_report_leaves_nothing_and_keeps_the_old_one(
    batches, tmp_path, monkeypatch, capsys, light_figures
):
    args = [str(batches["kinematic"]), "--study-reference-commands", "10"]
    new = tmp_path / "new" / "report"
    monkeypatch.setattr(storage, "open", FullDisk(tmp_path, allowed=2), raising=False)
    assert main(["report", *args, "--out", str(new)]) == 1
    _one_line(capsys.readouterr().err, "no space left on device", "nothing was written")
    assert not (tmp_path / "new").exists()  # the folders it made are gone too

    old = tmp_path / "old"
    monkeypatch.setattr(storage, "open", builtins.open, raising=False)
    assert main(["report", *args, "--out", str(old)]) == 0
    before = _files(old)
    monkeypatch.setattr(storage, "open", FullDisk(tmp_path, allowed=2), raising=False)
    assert main(["report", *args, "--out", str(old)]) == 1
    assert _files(old) == before


def test_disk_full_during_ablations_leaves_nothing(batches, tmp_path, monkeypatch, capsys):
    out = tmp_path / "out"
    monkeypatch.setattr(storage, "open", FullDisk(out, allowed=1), raising=False)
    batch = str(batches["kinematic"])
    args = ["ablations", batch, batch, "--out", str(out), "--study-reference-commands", "10"]
    assert main(args) == 1
    _one_line(capsys.readouterr().err, "no space left on device", "nothing was written")
    assert not out.exists()


# Read-only places -----------------------------------------------------------------------------
@pytest.fixture
def read_only(monkeypatch):
    """`read_only(directory)`: every way this process writes under `directory` fails as on a
    read-only file system (root, as the tests may run, ignores permission bits)."""
    roots: list[Path] = []
    real = {name: getattr(os, name) for name in ("open", "mkdir", "replace", "unlink", "rmdir")}
    real_open = builtins.open

    def inside(path) -> bool:
        if isinstance(path, int):  # an open file descriptor (a subprocess's pipe), not a path
            return False
        return any(Path(os.path.abspath(path)).is_relative_to(r) for r in roots)

    def refuse(path):
        raise OSError(errno.EROFS, os.strerror(errno.EROFS), str(path))

    def os_open(path, flags, *args, **kwargs):
        if inside(path) and flags & (os.O_WRONLY | os.O_RDWR | os.O_CREAT):
            refuse(path)
        return real["open"](path, flags, *args, **kwargs)

    def mkdir(path, *args, **kwargs):
        if inside(path):
            if os.path.exists(path):
                raise FileExistsError(errno.EEXIST, os.strerror(errno.EEXIST), str(path))
            refuse(path)
        return real["mkdir"](path, *args, **kwargs)

    def changing(name):
        def change(path, *args, **kwargs):
            if inside(path) or (args and inside(args[0])):
                refuse(path)
            return real[name](path, *args, **kwargs)

        return change

    def open_(path, mode="r", *args, **kwargs):
        if inside(path) and set(mode) & set("wax+"):
            refuse(path)
        return real_open(path, mode, *args, **kwargs)

    monkeypatch.setattr(os, "open", os_open)
    monkeypatch.setattr(os, "mkdir", mkdir)
    for name in ("replace", "unlink", "rmdir"):
        monkeypatch.setattr(os, name, changing(name))
    monkeypatch.setattr(builtins, "open", open_)
    monkeypatch.setattr(io, "open", open_)  # pathlib's
    return lambda directory: roots.append(Path(directory).resolve())


def test_eval_on_a_read_only_trial_is_one_line_before_any_work(
    batches, tmp_path, read_only, capsys
):
    trial = _copy_batch(batches["kinematic"], tmp_path / "batch") / "kinematic-random-seed0000"
    before = _files(trial)
    read_only(trial)
    assert main(["eval", str(trial), "--placements", "1", "--quiet"]) == 2
    _one_line(capsys.readouterr().err, f"cannot write into {trial}: read-only file system")
    assert _files(trial) == before


def _listing(directory: Path) -> dict[str, tuple[int, int]]:
    """Every entry under `directory`, with its size and modification time (ns)."""
    entries = [directory, *directory.rglob("*")]
    return {str(p): (p.stat().st_size, p.stat().st_mtime_ns) for p in entries}


# `compare` keeps its reference the same way (study_numbers), but plays 1000 commands in each
# backend for its grasp rates: too slow to run here.
@pytest.mark.parametrize("command", ["report", "ablations"])
def test_reports_write_nothing_into_the_batches_they_read(
    batches, tmp_path, monkeypatch, read_only, light_figures, command
):
    cache = tmp_path / "cache"
    monkeypatch.setenv(study_measure.CACHE_ENV, str(cache))
    batch = _copy_batch(batches["kinematic"], tmp_path / "batch")
    before = _listing(batch)
    read_only(batch)
    dirs = {"report": [batch], "ablations": [batch, batch]}
    args = [command, *map(str, dirs[command]), "--out", str(tmp_path / "out")]
    assert main([*args, "--study-reference-commands", "10"]) == 0
    assert _listing(batch) == before
    assert len(list(cache.glob("study-reference-*.parquet"))) == 1  # kept in the cache


def test_the_reference_cache_is_the_users_unless_told(monkeypatch, tmp_path):
    monkeypatch.delenv(study_measure.CACHE_ENV, raising=False)
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "xdg"))
    assert study_measure.reference_cache_dir() == tmp_path / "xdg" / "playroom"
    monkeypatch.setenv(study_measure.CACHE_ENV, str(tmp_path / "mine"))
    assert study_measure.reference_cache_dir() == tmp_path / "mine"


def test_a_cache_that_cannot_be_written_does_not_fail_the_report(
    batches, tmp_path, monkeypatch, light_figures
):
    not_a_folder = tmp_path / "file"
    not_a_folder.write_text("x")
    monkeypatch.setenv(study_measure.CACHE_ENV, str(not_a_folder / "cache"))
    page = write_report(batches["kinematic"], tmp_path / "out", measures=room_measures(10))
    assert "as the study computed it" in page.read_text()


def test_a_report_into_a_read_only_place_is_refused_before_any_work(
    batches, tmp_path, read_only, monkeypatch
):
    from experiments.report import batch_report

    def no_work(*args, **kwargs):
        raise AssertionError("the report should have been refused before its work")

    monkeypatch.setattr(batch_report, "summarise_batch", no_work)
    read_only(tmp_path)
    with pytest.raises(ReportError, match="cannot write into .*: read-only file system"):
        write_report(batches["kinematic"], tmp_path / "out", measures=room_measures(10))


# Messages that say what is true ---------------------------------------------------------------
def test_another_tools_folder_is_not_called_a_batch_of_unevaluated_trials(tmp_path, batches):
    other = tmp_path / "other"
    (other / "run-1").mkdir(parents=True)
    (other / "run-1" / "config.json").write_text('{"lr": 0.1}')  # another tool's config
    (other / "notes.txt").write_text("x")
    with pytest.raises(ReportError) as info:
        write_report(other, tmp_path / "out", measures=room_measures(10))
    message = str(info.value)
    assert "no trial directories found in" in message and "playroom batch" in message
    assert "eval" not in message
    trial = batches["kinematic"] / "kinematic-random-seed0000"
    with pytest.raises(ReportError, match="is a trial directory, not a batch"):
        write_report(trial, tmp_path / "out", measures=room_measures(10))
    assert not (tmp_path / "out").exists()


def test_write_files_is_all_or_nothing(tmp_path, monkeypatch):
    folder = tmp_path / "a" / "b"
    monkeypatch.setattr(storage, "open", FullDisk(tmp_path, allowed=1), raising=False)
    with pytest.raises(storage.WriteError) as info:
        storage.write_files(folder, {"one": b"1", "two": b"2"})
    assert info.value.filename == str(folder / "two") and info.value.errno == errno.ENOSPC
    assert not (tmp_path / "a").exists()
    monkeypatch.undo()
    assert storage.write_files(folder, {"one": b"1", "two": b"2"})[-1] == folder / "two"
    assert _files(folder) == {"one": b"1", "two": b"2"}


# Requests that ended in a traceback: one line, exit code 2, nothing written ------
TRACEBACKS = {
    # pyarrow could not write the seed into the log's int64 column.
    "seed beyond int64": (["--seed", "99999999999999999999999"], "seed must be"),
    # A 14.6 TiB allocation, and a dimension beyond NumPy's: after config.json was written.
    "window of 14.6 TiB": (["--set", "learner.progress_window=100000000000"], "progress_window"),
    "window beyond NumPy": (["--set", "learner.progress_window=99999999999999999999"], "window"),
}


@pytest.mark.parametrize("request_", TRACEBACKS, ids=list(TRACEBACKS))
def test_a_request_that_raised_a_traceback_is_one_line_and_writes_nothing(
    tmp_path, capsys, request_
):
    args, says = TRACEBACKS[request_]
    out = tmp_path / "t"
    assert main(["run", "--out", str(out), "--iterations", "40", "--quiet", *args]) == 2
    _one_line(capsys.readouterr().err, says, args[-1].split("=")[-1])
    assert not out.exists()  # the same directory is free for the corrected command


def test_a_symlink_loop_as_out_is_one_line_and_changes_nothing(tmp_path, capsys):
    loop = tmp_path / "loop"
    loop.symlink_to(loop)
    assert main(["run", "--out", str(loop), "--iterations", "40", "--quiet"]) == 2
    _one_line(capsys.readouterr().err, str(loop), "symbolic link")
    assert list(tmp_path.iterdir()) == [loop] and loop.is_symlink()
