"""`playroom eval` writes into a trial as its one writer: it takes the trial's lock before it
reads anything (a live writer is named, never a checkpoint caught mid-rename), and it removes
the temporary files that killed writers left there."""

from __future__ import annotations

import os
import shutil
import subprocess
import sys

import pytest

from experiments.cli.main import main
from experiments.run.settings import TrialSettings
from experiments.run.trial import run_trial
from experiments.trial_dir.layout import (
    CHECKPOINT_FILE,
    COMPETENCE_FILE,
    EVAL_FILE,
    LOCK_FILE,
    PREVIOUS_CHECKPOINT_FILE,
    VOCAL_FILE,
)

# A writer that holds a trial's lock until its standard input is closed.
HOLD_LOCK = """
import sys
from experiments.trial_dir.lock import DirectoryLock
DirectoryLock(sys.argv[1]).acquire()
print("locked", flush=True)
sys.stdin.read()
"""


@pytest.fixture(scope="module")
def base(tmp_path_factory):
    out = tmp_path_factory.mktemp("base") / "trial"
    run_trial(out, TrialSettings(iterations=200, seed=3, checkpoint_every=100), progress=False)
    return out


def _copy(base, tmp_path):
    out = tmp_path / "trial"
    shutil.copytree(base, out)
    return out


def _contents(out) -> dict:
    return {p: p.read_bytes() for p in out.rglob("*") if p.is_file() and p.name != LOCK_FILE}


def _eval(out, capsys) -> tuple[int, list[str]]:
    code = main(["eval", str(out), "--quiet", "--placements", "1"])
    return code, capsys.readouterr().err.strip().splitlines()


def test_eval_during_a_live_run_names_the_writer_not_a_missing_checkpoint(base, tmp_path, capsys):
    out = _copy(base, tmp_path)
    writer = subprocess.Popen(
        [sys.executable, "-c", HOLD_LOCK, str(out)],
        stdin=subprocess.PIPE,
        stdout=subprocess.PIPE,
        text=True,
    )
    try:
        assert writer.stdout is not None and writer.stdout.readline().strip() == "locked"
        # The writer's window between its two checkpoint lines (experiments/run/trial.py): the
        # newest checkpoint renamed to the previous one, the new one not yet written.
        os.replace(out / CHECKPOINT_FILE, out / PREVIOUS_CHECKPOINT_FILE)
        before = _contents(out)
        code, err = _eval(out, capsys)
    finally:
        assert writer.stdin is not None
        writer.stdin.close()
        writer.wait()
    assert code == 2 and len(err) == 1, err
    assert f"pid {writer.pid}" in err[0] and "missing" not in err[0], err[0]
    assert _contents(out) == before


def _dead_pid() -> int:
    proc = subprocess.Popen([sys.executable, "-c", "pass"])
    proc.wait()
    return proc.pid


def test_eval_removes_the_temporary_files_of_a_killed_eval(base, tmp_path, capsys):
    out = _copy(base, tmp_path)
    dead = _dead_pid()
    litter = [out / f".{name}.{dead}.tmp" for name in (COMPETENCE_FILE, VOCAL_FILE)]
    for path in litter:
        path.write_bytes(b"half a table")
    live = subprocess.Popen([sys.executable, "-c", "import sys; sys.stdin.read()"],
                            stdin=subprocess.PIPE)  # fmt: skip
    try:
        spared = out / f".video.mp4.{live.pid}.tmp"  # a live writer that takes no lock
        spared.write_bytes(b"being written")
        code, err = _eval(out, capsys)
    finally:
        assert live.stdin is not None
        live.stdin.close()
        live.wait()
    assert code == 0 and (out / EVAL_FILE).exists()
    assert not any(path.exists() for path in litter) and spared.exists()
    assert any("temporary file" in line and litter[0].name in line for line in err), err
