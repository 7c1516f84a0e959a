"""`playroom cluster` without --print-script: it submits its jobs, says where to send a batch,
and Ctrl-C cancels the jobs; a job the queue refuses is one line, the others cancelled. No job
queue here: a stand-in `sbatch` runs each job's script on this machine in a process group of its
own (its id the job's), and `scancel` ends that group, so the real script starts real workers
that join the command's scheduler."""

from __future__ import annotations

import os
import queue
import re
import signal
import subprocess
import sys
import threading
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
# Generous bounds for a loaded machine (s): they end a hung test, they measure nothing.
LINE_TIMEOUT_S = 120
EXIT_TIMEOUT_S = 60

SBATCH = """#!/usr/bin/env bash
# sbatch on this machine: the job's script, copied before dask-jobqueue deletes it, run in the
# background in a new session (its process group's id is the job's).
script=$(mktemp "{jobs}/job.XXXXXX")
cp "$1" "$script"
setsid bash "$script" > "$script.log" 2>&1 < /dev/null &
echo "$!" >> "{jobs}/submitted"
echo "Submitted batch job $!"
"""
# sbatch taking the first job (without running it) and refusing the others, as a queue does past
# a user's limit. mkdir: one job is first however many are submitted at once.
SBATCH_LIMITED = """#!/usr/bin/env bash
if mkdir "{jobs}/first" 2>/dev/null; then
  echo 101 >> "{jobs}/submitted"; echo "Submitted batch job 101"
else echo "sbatch: error: QOSMaxSubmitJobPerUserLimit" >&2; exit 1; fi
"""
SCANCEL = """#!/usr/bin/env bash
for job in "$@"; do echo "$job" >> "{jobs}/cancelled"; kill -- "-$job" 2>/dev/null; done
exit 0
"""


def _job_queue(tmp_path: Path, sbatch: str = SBATCH) -> tuple[Path, Path]:
    """(the folder of the stand-ins, the folder where they record the jobs)."""
    bin_dir, jobs = tmp_path / "bin", tmp_path / "jobs"
    bin_dir.mkdir()
    jobs.mkdir()
    for name, text in (("sbatch", sbatch), ("scancel", SCANCEL)):
        (bin_dir / name).write_text(text.format(jobs=jobs))
        (bin_dir / name).chmod(0o755)
    return bin_dir, jobs


def _ids(path: Path) -> list[int]:
    return [int(line) for line in path.read_text().split()] if path.exists() else []


def _alive(group: int) -> bool:
    try:
        os.killpg(group, 0)
    except ProcessLookupError:
        return False
    return True


def _lines(stream, into: queue.Queue) -> None:
    for line in stream:
        into.put(line.rstrip("\n"))


def _wait_for(lines: queue.Queue, pattern: str, seen: list[str]) -> re.Match:
    while True:
        line = lines.get(timeout=LINE_TIMEOUT_S)
        seen.append(line)
        if found := re.search(pattern, line):
            return found


def _interruptible() -> None:
    signal.signal(signal.SIGINT, signal.SIG_DFL)


@pytest.mark.slow  # starts a scheduler and two jobs of worker processes: ~10 s
def test_the_jobs_workers_join_the_printed_scheduler_and_ctrl_c_cancels_them(tmp_path):
    from distributed import Client

    bin_dir, jobs = _job_queue(tmp_path)
    scratch = tmp_path / "scratch"
    command = subprocess.Popen(
        [sys.executable, "-m", "experiments.cli.main", "cluster", "slurm", "--jobs", "2",
         "--cores", "1", "--memory", "2GB", "--walltime", "00:10:00", "--scratch", str(scratch)],
        cwd=tmp_path, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
        env={**os.environ, "PATH": f"{bin_dir}{os.pathsep}{os.environ['PATH']}",
             "PYTHONPATH": str(ROOT)},
        # Ctrl-C as a terminal gives it: pytest-xdist's workers ignore SIGINT, and a child
        # inherits that (Python then installs no KeyboardInterrupt for it).
        preexec_fn=_interruptible,
    )  # fmt: skip
    lines: queue.Queue = queue.Queue()
    threading.Thread(target=_lines, args=(command.stdout, lines), daemon=True).start()
    seen: list[str] = []
    try:
        address = _wait_for(lines, r"^scheduler: (tcp://\S+) ", seen).group(1)
        batch = _wait_for(lines, r"^run a batch on them: (.*)$", seen).group(1)
        assert batch.startswith(f"playroom batch --scheduler {address} ")
        _wait_for(lines, r"^workers connected: 2 of 2$", seen)
        assert len(_ids(jobs / "submitted")) == 2
        with Client(address, timeout="10s") as client:
            workers = client.scheduler_info(n_workers=-1)["workers"].values()
            assert [w["nthreads"] for w in workers] == [1, 1]
            assert all(Path(w["local_directory"]).is_relative_to(scratch) for w in workers)

        command.send_signal(signal.SIGINT)
        assert command.wait(timeout=EXIT_TIMEOUT_S) == 128 + signal.SIGINT
        err = command.stderr.read()
        assert err.startswith("playroom cluster: interrupted; its scheduler is closed and its jobs")
        assert sorted(_ids(jobs / "cancelled")) == sorted(_ids(jobs / "submitted"))
    finally:
        if command.poll() is None:
            command.kill()
            command.wait()
        for job in _ids(jobs / "submitted"):
            if _alive(job):
                os.killpg(job, signal.SIGKILL)
    assert seen[-1] == "workers connected: 2 of 2", seen


CLUSTER = ["cluster", "slurm", "--cores", "1", "--memory", "2GB", "--walltime", "00:10:00"]


def test_a_refused_job_is_one_line_and_the_jobs_taken_are_cancelled(tmp_path, monkeypatch, capsys):
    from experiments.cli.main import main

    bin_dir, jobs = _job_queue(tmp_path, SBATCH_LIMITED)
    monkeypatch.setenv("PATH", f"{bin_dir}{os.pathsep}{os.environ['PATH']}")
    assert main([*CLUSTER, "--jobs", "3"]) == 2
    captured = capsys.readouterr()
    assert captured.out == ""
    assert captured.err == (
        "playroom cluster: error: sbatch refused a job: "
        "sbatch: error: QOSMaxSubmitJobPerUserLimit\n"
    )
    assert _ids(jobs / "submitted") == [101] and _ids(jobs / "cancelled") == [101]


def test_without_the_job_queues_command_it_says_where_to_run(tmp_path, monkeypatch, capsys):
    from experiments.cli.main import main

    monkeypatch.setenv("PATH", str(tmp_path))  # no sbatch there
    assert main(CLUSTER) == 2
    assert capsys.readouterr().err == (
        "playroom cluster: error: no sbatch on this machine: run `playroom cluster slurm` on a "
        "login node of the cluster, where sbatch submits jobs\n"
    )
