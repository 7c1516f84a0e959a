"""`playroom cluster`'s job scripts (experiments/batches/jobqueue.py), made by dask-jobqueue
without a job queue: what docs/usage.md shows is what the command prints; a job asks for the
cores, memory and time it was given and starts a local batch's workers (one process of one
thread per core); the script's environment is the project's, with the local batch's settings,
and a node that does not see it stops the job with one line; bad requests are one line."""

from __future__ import annotations

import json
import re
import shlex
import subprocess
import sys
from pathlib import Path

import pytest
from distributed.cli.dask_worker import main as dask_worker_command

from experiments.batches.jobqueue import (
    DEFAULT_SCRATCH,
    SCHEDULER_PLACEHOLDER,
    THREAD_VARIABLES,
    JobSpec,
    environment_lines,
    job_script,
)
from experiments.batches.scheduler import LOCAL_WORKER_CONFIG
from experiments.cli.main import main

ROOT = Path(__file__).resolve().parents[2]
USAGE = ROOT / "docs" / "usage.md"
# Where docs/usage.md's script has the environment the command runs from.
DOCS_ENVIRONMENT = "/home/you/playroom/.venv"
DOCS_COMMAND = re.compile(r"^(playroom cluster slurm [^\n]*--print-script)$", re.M)
SCRIPT_BLOCK = re.compile(r"^```bash\n(.*?)^```", re.M | re.S)
# SLURM's and PBS's memory units are binary, whatever their names (G, GB, MB).
BINARY_UNITS = {"K": 2**10, "M": 2**20, "G": 2**30, "T": 2**40}

SPEC = {"cores": 3, "memory": "12GB", "walltime": "02:30:00", "queue": "long", "account": "lab42"}


def _documented() -> tuple[str, str]:
    """docs/usage.md's `playroom cluster slurm ... --print-script` and the script shown after it."""
    text = USAGE.read_text()
    (command,) = DOCS_COMMAND.findall(text)
    script = SCRIPT_BLOCK.search(text, text.index(command))
    assert script is not None, "no ```bash block after the command in docs/usage.md"
    return command, script.group(1)


def _worker_options(script: str) -> tuple[str, dict]:
    """The worker command's interpreter and its options as `dask worker` parses them."""
    (line,) = [w for w in script.splitlines() if "-m distributed.cli.dask_worker " in w]
    python, _, module, *args = shlex.split(line)
    assert module == "distributed.cli.dask_worker"
    return python, dask_worker_command.make_context("dask-worker", args).params


def _binary_bytes(text: str) -> int:
    number, unit = re.fullmatch(r"(\d+)([kKMGT])B?", text).groups()
    return int(number) * BINARY_UNITS[unit.upper()]


def _directives(script: str, prefix: str) -> list[str]:
    return [line.removeprefix(prefix) for line in script.splitlines() if line.startswith(prefix)]


def test_the_slurm_script_the_docs_show_is_the_one_the_command_prints(capsys):
    command, documented = _documented()
    assert main(shlex.split(command)[1:]) == 0
    printed = capsys.readouterr().out
    # The one difference allowed: the path of the environment the command runs from.
    assert sys.prefix in printed
    assert printed.replace(sys.prefix, DOCS_ENVIRONMENT) == documented


@pytest.mark.parametrize("system", ["slurm", "pbs"])
def test_a_job_starts_one_single_threaded_worker_per_core_in_this_environment(system):
    script = job_script(JobSpec(system=system, **SPEC))
    python, options = _worker_options(script)
    assert python == sys.executable
    assert f"source {Path(sys.prefix) / 'bin' / 'activate'}" in script.splitlines()
    assert options["scheduler"] == SCHEDULER_PLACEHOLDER
    # As a local batch's LocalCluster (experiments/batches/scheduler.py: connect): worker
    # processes under a nanny, one thread each, as many as the job's cores.
    assert options["nthreads"] == 1 and int(options["n_workers"]) == SPEC["cores"]
    assert options["nanny"] is True
    # The job's 12 GB shared evenly, written to the hundredth of a GiB.
    per_worker = float(options["memory_limit"].removesuffix("GiB")) * 2**30
    assert abs(per_worker - 12e9 / SPEC["cores"]) <= 0.005 * 2**30
    assert options["local_directory"] == DEFAULT_SCRATCH


def test_a_slurm_job_asks_for_the_cores_memory_time_queue_and_account():
    directives = _directives(job_script(JobSpec(system="slurm", **SPEC)), "#SBATCH ")
    assert {"-n 1", f"--cpus-per-task={SPEC['cores']}", "-t 02:30:00"} <= set(directives)
    assert {"-p long", "-A lab42"} <= set(directives)
    (memory,) = [d.removeprefix("--mem=") for d in directives if d.startswith("--mem=")]
    assert 12e9 <= _binary_bytes(memory) < 12e9 + 2**30  # the next whole GiB


def test_a_pbs_job_asks_for_the_cores_memory_time_queue_and_account():
    directives = _directives(job_script(JobSpec(system="pbs", **SPEC)), "#PBS ")
    assert {"-q long", "-A lab42", "-l walltime=02:30:00"} <= set(directives)
    (select,) = [d for d in directives if d.startswith("-l select=")]
    resources = dict(r.split("=") for r in select.removeprefix("-l select=1:").split(":"))
    assert resources["ncpus"] == str(SPEC["cores"])
    assert 12e9 <= _binary_bytes(resources["mem"]) < 12e9 + 2**30  # the next whole GiB


def test_the_scripts_environment_is_the_projects_with_the_local_batchs_settings(tmp_path):
    # The script up to its worker command, run as the job's shell runs it, then the Python its
    # PATH finds: the project's environment, one thread per library, Dask's settings of a local
    # batch's workers.
    script = job_script(JobSpec(system="slurm", **SPEC))
    before_workers = script[: script.index(sys.executable + " -m distributed")]
    probe = (
        "import json, os, sys, dask, experiments; print(json.dumps({'prefix': sys.prefix, "
        f"'threads': [os.environ.get(n) for n in {list(THREAD_VARIABLES)!r}], "
        f"'dask': [dask.config.get(k) for k in {list(LOCAL_WORKER_CONFIG)!r}]}}))"
    )
    done = subprocess.run(
        ["bash", "-c", f"{before_workers}\npython -c {shlex.quote(probe)}"],
        capture_output=True, text=True, cwd=tmp_path, env={"PATH": "/usr/bin:/bin"},
    )  # fmt: skip
    assert done.returncode == 0, done.stderr
    seen = json.loads(done.stdout)
    assert seen["prefix"] == sys.prefix
    assert seen["threads"] == ["1"] * len(THREAD_VARIABLES)
    assert seen["dask"] == list(LOCAL_WORKER_CONFIG.values())


def test_the_script_says_the_batch_directory_must_be_shared():
    script = job_script(JobSpec(system="pbs", **SPEC))
    comments = " ".join(line[2:] for line in script.splitlines() if line.startswith("# "))
    shared = "The batch directory (playroom batch --out) must be on a file system every node sees"
    assert f"{shared} at the same path" in comments


def test_a_node_that_does_not_see_the_environment_stops_the_job_with_one_line(tmp_path):
    missing = tmp_path / "elsewhere" / ".venv"
    lines = environment_lines(str(missing / "bin" / "python"), str(missing), sys.base_prefix)
    done = subprocess.run(
        ["bash", "-c", "\n".join([*lines, "echo workers started"])],
        capture_output=True, text=True,
    )  # fmt: skip
    assert done.returncode == 1 and done.stdout == ""
    assert done.stderr.count("\n") == 1 and str(missing / "bin" / "python") in done.stderr


def test_an_interpreter_outside_a_virtual_environment_is_used_by_its_path_alone():
    lines = environment_lines(
        "/opt/conda/envs/lab/bin/python", "/opt/conda/envs/lab", "/opt/conda/envs/lab"
    )
    assert not [line for line in lines if line.startswith("source ")]
    assert "test -x /opt/conda/envs/lab/bin/python" in lines[1]


@pytest.mark.parametrize(
    "change, named",
    [
        (["--memory", "16gigs"], "--memory '16gigs' is not a size"),
        (["--memory", "0GB"], "--memory '0GB' is not a size"),
        (["--walltime", "12h"], "--walltime '12h' is not HH:MM:SS"),
        (["--walltime", "12:75:00"], "--walltime '12:75:00' is not HH:MM:SS"),
        (["--interface", "no-such-nic0"], "--interface: 'no-such-nic0' is not a valid network"),
    ],
)
def test_a_bad_request_is_one_line_naming_the_option(capsys, change, named):
    args = {"--cores": "2", "--memory": "8GB", "--walltime": "01:00:00"}
    args.update(dict([change]))
    argv = ["cluster", "slurm", *[w for pair in args.items() for w in pair], "--print-script"]
    assert main(argv) == 2
    captured = capsys.readouterr()
    assert captured.out == ""
    assert captured.err.startswith(f"playroom cluster: error: {named}")
    assert captured.err.count("\n") == 1


def test_ctrl_c_stays_the_commands_once_dask_jobqueue_is_imported():
    # dask-jobqueue's import sets a SIGINT handler that exits: `playroom cluster` ended with
    # exit code 0 and no line on Ctrl-C. A fresh process: here it is imported already.
    probe = (
        "import signal\n"
        "def own(*args): pass\n"
        "signal.signal(signal.SIGINT, own)\n"
        "from experiments.batches.jobqueue import job_script, JobSpec\n"
        "job_script(JobSpec('slurm', cores=1, memory='2GB', walltime='01:00:00'))\n"
        "assert signal.getsignal(signal.SIGINT) is own, signal.getsignal(signal.SIGINT)\n"
    )
    done = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True, cwd=ROOT)
    assert done.returncode == 0, done.stderr


def test_without_the_cluster_extra_the_command_says_how_to_install_it(capsys, monkeypatch):
    monkeypatch.setitem(sys.modules, "dask_jobqueue", None)  # import raises ImportError
    argv = ["cluster", "pbs", "--cores", "2", "--memory", "8GB", "--walltime", "01:00:00"]
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert err.startswith("playroom cluster: error: dask-jobqueue is not installed")
    assert '".[cluster]"' in err and err.count("\n") == 1
