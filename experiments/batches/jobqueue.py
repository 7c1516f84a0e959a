"""Workers for batches on a SLURM or PBS cluster, submitted as jobs by dask-jobqueue.

`playroom cluster` starts a Dask scheduler in its own process (on the login node), submits jobs
whose script starts Dask workers that connect to it, and keeps them until it is stopped;
`playroom batch --scheduler ADDRESS` then sends its trials there. Each job's script (what
`job_script` returns) is dask-jobqueue's, with the project's settings:
- the environment this command runs in, activated on the node: its interpreter (and, for a
  virtual environment, its `activate`) must lie on a file system every node sees at the same
  path, and the script stops with one line in the job's log where the node does not see it;
- the workers of a local batch (experiments/batches/scheduler.py): one process per core, each
  running one trial at a time on one thread, numerical libraries on one thread too, and Dask's
  settings of `LOCAL_WORKER_CONFIG`;
- a node-local scratch directory for the workers' own directories and Dask's spill files;
- a reminder that the batch directory must be on a file system every node sees at the same path
  (the workers write the trials there).

dask-jobqueue is the `cluster` extra (`pip install -e ".[cluster]"`); only this module and the
command that calls it import it. Settings of a site's dask-jobqueue configuration
(~/.config/dask/jobqueue.yaml) that the project does not set here, such as extra directives,
apply as dask-jobqueue documents.
"""

from __future__ import annotations

import dataclasses
import re
import shlex
import shutil
import signal
import sys
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any

from experiments.batches.scheduler import LOCAL_WORKER_CONFIG
from experiments.run import stop_requests

# The job queues, by the name the command takes, and their dask-jobqueue cluster classes.
SYSTEMS = {"slurm": "SLURMCluster", "pbs": "PBSCluster"}
# The name of the jobs in the queue (squeue, qstat).
JOB_NAME = "playroom-workers"
# Jobs the command submits when not told.
DEFAULT_JOBS = 1
# Threads per worker process: a trial is one Dask task that holds its thread from start to end,
# so one thread per process and one process per core, as a local batch (scheduler.connect).
THREADS_PER_WORKER = 1
# The numerical libraries' thread pools, one thread per worker: as Dask's nanny sets them
# (distributed.nanny.pre-spawn-environ), written in the script so that a site's Dask
# configuration cannot change them.
THREAD_VARIABLES = ("OMP_NUM_THREADS", "MKL_NUM_THREADS", "OPENBLAS_NUM_THREADS")
# Where the workers keep their directories and spill files: the node's own disk, not the shared
# file system. Expanded by the job's shell: the job's $TMPDIR (PBS sets one per job, many
# SLURM sites too), else /tmp.
DEFAULT_SCRATCH = "${TMPDIR:-/tmp}"
# How long a worker waits for the scheduler before it exits (s; dask-jobqueue's default): a job
# that starts after the command stopped ends by itself.
DEATH_TIMEOUT_S = 60
# The scheduler listens on any free port, and its dashboard on another: a login node is shared
# (Dask's 8786 and 8787 may be another user's).
SCHEDULER_PORT = 0
DASHBOARD_ADDRESS = ":0"
# The scheduler's address in a printed script (`job_script`): the scheduler started only to
# make it is closed at once, and the command that submits jobs starts another.
SCHEDULER_PLACEHOLDER = "tcp://SCHEDULER:PORT"
# How often a running cluster looks for workers joining or leaving (s).
WORKER_POLL_S = 5
WALLTIME = re.compile(r"\d+:[0-5]\d:[0-5]\d")


class ClusterError(Exception):
    """A cluster that cannot be set up as asked: the message says why and what to do, in one
    line."""


@dataclasses.dataclass(frozen=True)
class JobSpec:
    """One job of workers: its queue, its size and its workers' scratch directory."""

    system: str  # a key of SYSTEMS
    cores: int  # per job: as many worker processes
    memory: str  # per job, e.g. "16GB", shared evenly by its workers
    walltime: str  # HH:MM:SS
    queue: str | None = None  # SLURM's partition, PBS's queue; None: the site's default
    account: str | None = None  # charged for the jobs; None: the user's default
    interface: str | None = None  # the network the workers and scheduler talk over, e.g. ib0
    scratch: str = DEFAULT_SCRATCH

    def __post_init__(self) -> None:
        from dask.utils import parse_bytes

        if self.system not in SYSTEMS:
            raise ClusterError(f"unknown job queue {self.system!r}: choose from {list(SYSTEMS)}")
        if self.cores <= 0:
            raise ClusterError(f"--cores must be > 0, got {self.cores}")
        try:
            memory = parse_bytes(self.memory)
        except (ValueError, TypeError):
            memory = 0
        if memory <= 0:
            raise ClusterError(f"--memory {self.memory!r} is not a size: give one like 16GB")
        if not WALLTIME.fullmatch(self.walltime):
            raise ClusterError(f"--walltime {self.walltime!r} is not HH:MM:SS, e.g. 12:00:00")
        if self.interface is not None:
            from distributed.utils import get_ip_interface

            try:  # here, where the scheduler listens; each node checks its own
                get_ip_interface(self.interface)
            except ValueError as exc:  # names the interfaces there are
                raise ClusterError(f"--interface: {exc}") from None


def environment_lines(
    python: str = sys.executable, prefix: str = sys.prefix, base_prefix: str = sys.base_prefix
) -> list[str]:
    """The lines a job runs before its workers: the environment of `python` activated (a
    virtual environment's `activate` when `prefix` is one), one thread per library, the local
    batch's Dask settings, and the shared file system the batch directory needs."""
    quoted = shlex.quote(python)
    lines = [
        "# The project's environment: on a file system every node sees at this path.",
        f"test -x {quoted} || {{ echo {shlex.quote(_missing_line(python))} >&2; exit 1; }}",
    ]
    if prefix != base_prefix:  # a virtual environment: its scripts on PATH
        lines.append(f"source {shlex.quote(str(Path(prefix) / 'bin' / 'activate'))}")
    lines.append("# One thread per worker process, the numerical libraries' too.")
    lines += [f"export {name}={THREADS_PER_WORKER}" for name in THREAD_VARIABLES]
    lines.append(
        "# The Dask settings of a local batch's workers (experiments/batches/scheduler.py)."
    )
    lines += [f"export {name}={value}" for name, value in dask_environment().items()]
    lines.append("# The batch directory (playroom batch --out) must be on a file system every node")
    lines.append("# sees at the same path: the workers write the trials there.")
    return lines


def _missing_line(python: str) -> str:
    return f"playroom: no {python} on this node: it must be on a file system every node sees"


def dask_environment(config: dict[str, str] = LOCAL_WORKER_CONFIG) -> dict[str, str]:
    """Dask settings as the environment variables Dask reads them from ("distributed.admin.
    tick.interval" -> DASK_DISTRIBUTED__ADMIN__TICK__INTERVAL)."""
    return {
        "DASK_" + "__".join(part.upper().replace("-", "_") for part in key.split(".")): value
        for key, value in config.items()
    }


def _cluster_class(system: str) -> Any:
    # Importing dask-jobqueue sets a SIGINT handler that exits (its runner module, at import):
    # Ctrl-C would end the command with exit code 0 and no line. The command's own is kept.
    sigint = signal.getsignal(signal.SIGINT)
    try:
        import dask_jobqueue
    except ImportError:
        raise ClusterError(
            "dask-jobqueue is not installed: install the cluster extra with "
            '`pip install --constraint constraints.txt -e ".[cluster]"` (docs/usage.md)'
        ) from None
    finally:
        if sigint is not None and signal.getsignal(signal.SIGINT) is not sigint:
            signal.signal(signal.SIGINT, sigint)
    return getattr(dask_jobqueue, SYSTEMS[system])


@contextmanager
def started_cluster(spec: JobSpec, dashboard: bool = True) -> Iterator[Any]:
    """dask-jobqueue's cluster of `spec`, its scheduler started in this process (no jobs yet);
    closed on the way out, cancelling every job it submitted."""
    cls = _cluster_class(spec.system)
    # Without a dashboard the scheduler still serves HTTP (its health check): on a free port too.
    scheduler_options = {
        "port": SCHEDULER_PORT,
        "dashboard_address": DASHBOARD_ADDRESS,
        "dashboard": dashboard,
    }
    cluster = cls(
        cores=spec.cores,
        processes=spec.cores // THREADS_PER_WORKER,
        memory=spec.memory,
        walltime=spec.walltime,
        queue=spec.queue,
        account=spec.account,
        interface=spec.interface,
        job_name=JOB_NAME,
        python=sys.executable,
        job_script_prologue=environment_lines(),
        local_directory=spec.scratch,
        death_timeout=DEATH_TIMEOUT_S,
        scheduler_options=scheduler_options,
    )
    with cluster:
        yield cluster


def job_script(spec: JobSpec) -> str:
    """The script each job of `spec` runs, as dask-jobqueue writes it (the worker's name
    "dummy-name" is given each job its own), the scheduler's address `SCHEDULER_PLACEHOLDER`."""
    with started_cluster(spec, dashboard=False) as cluster:
        return cluster.job_script().replace(cluster.scheduler_address, SCHEDULER_PLACEHOLDER)


def serve(spec: JobSpec, jobs: int, say: Callable[[str], None]) -> None:
    """Submit `jobs` jobs of `spec` and keep their scheduler until interrupted (Ctrl-C,
    SIGTERM), saying where to send a batch and each change in the workers connected; the jobs
    are cancelled on the way out."""
    submit = _cluster_class(spec.system).job_cls.submit_command
    if shutil.which(submit) is None:
        raise ClusterError(
            f"no {submit} on this machine: run `playroom cluster {spec.system}` on a login node "
            f"of the cluster, where {submit} submits jobs"
        )
    with started_cluster(spec) as cluster:
        _submit(cluster, jobs, submit)
        address = cluster.scheduler_address
        say(f"scheduler: {address} (dashboard: {cluster.dashboard_link})")
        say(f"submitted {jobs} {spec.system} job(s) of {spec.cores} worker(s) each")
        say(
            f"run a batch on them: playroom batch --scheduler {address} --profile NAME --out DIR"
            " (DIR on a file system every node sees at the same path)"
        )
        say("stop with Ctrl-C: the jobs are cancelled")
        seen = -1
        while True:
            connected = len(cluster.scheduler_info.get("workers", {}))
            if connected != seen:
                say(f"workers connected: {connected} of {jobs * spec.cores}")
                seen = connected
            time.sleep(WORKER_POLL_S)
            stop_requests.raise_if_requested()


def _submit(cluster: Any, jobs: int, submit: str) -> None:
    """Submit `jobs` jobs, waiting for the queue's answers: where it refuses one, those it took
    are cancelled and ClusterError gives its reason. Not `cluster.scale`, which submits in the
    background, where a refusal is only logged and the command would wait for jobs that never
    come."""
    for _ in range(jobs):
        cluster.worker_spec.update(cluster.new_worker_spec())

    async def submitted() -> None:
        await cluster  # a SpecCluster starts the workers of its spec, raising their failures

    try:
        cluster.sync(submitted)
        return
    except (RuntimeError, ValueError) as exc:  # the command failed, or printed no job id
        reason = _refusal(str(exc))
    cluster.sync(_cancel_all, cluster)
    raise ClusterError(f"{submit} refused a job: {reason}")


async def _cancel_all(cluster: Any) -> None:
    """Cancel every job `cluster` submitted and forget them all. dask-jobqueue's `Job.close`
    cancels a job without marking it closed, and a job never submitted stays "created": closing
    the cluster would then fail on distributed's check that every worker it made is closed."""
    from distributed.core import Status

    for job in cluster.workers.values():
        await job.close()  # nothing to cancel for a job without an id
        job.status = Status.closed
    cluster.workers.clear()
    cluster.worker_spec.clear()


def _refusal(message: str) -> str:
    """What the job queue said, on one line: dask-jobqueue's message ends with the command's
    stderr, after "stderr:"."""
    said = message.rpartition("stderr:")[2] if "stderr:" in message else message
    return " ".join(said.split()) or " ".join(message.split())
