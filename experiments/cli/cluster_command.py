"""`playroom cluster`: Dask workers for batches, submitted as SLURM or PBS jobs by dask-jobqueue
(experiments/batches/jobqueue.py)."""

from __future__ import annotations

import argparse

from experiments.batches.jobqueue import DEFAULT_JOBS, DEFAULT_SCRATCH, SYSTEMS
from experiments.cli.args import UsageError, positive_int


def add_parsers(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "cluster",
        help="Dask workers for batches as SLURM or PBS jobs (the cluster extra)",
        description="Start a Dask scheduler here (the login node), submit jobs that start its "
        "workers, print the `playroom batch --scheduler` line that uses them, and keep them "
        "until Ctrl-C, which cancels the jobs. Run it from the project's environment on a file "
        "system every node sees at the same path: the jobs start that environment. Needs the "
        "cluster extra (dask-jobqueue; docs/usage.md, On a cluster).",
    )
    p.add_argument("system", choices=list(SYSTEMS), help="the cluster's job queue")
    p.add_argument(
        "--jobs",
        type=positive_int,
        default=DEFAULT_JOBS,
        metavar="N",
        help="jobs to submit, each of --cores workers",
    )
    p.add_argument(
        "--cores",
        type=positive_int,
        required=True,
        metavar="N",
        help="cores per job: as many worker processes of one thread, each running one trial "
        "at a time",
    )
    p.add_argument(
        "--memory",
        required=True,
        metavar="SIZE",
        help="memory per job, shared evenly by its workers, e.g. 16GB (GB = 10^9 bytes, GiB = "
        "2^30); a trial of 10^6 iterations peaks near 1.2 GB (docs/speed.md)",
    )
    p.add_argument(
        "--walltime",
        required=True,
        metavar="HH:MM:SS",
        help="each job's time limit; a trial stopped by it resumes from its last checkpoint "
        "when the batch runs again",
    )
    p.add_argument("--queue", help="the queue (SLURM: partition) (default: the site's)")
    p.add_argument("--account", help="the account charged for the jobs (default: yours)")
    p.add_argument(
        "--interface",
        metavar="NAME",
        help="the network interface the scheduler and workers talk over, e.g. ib0 (default: "
        "the address of this machine's host name)",
    )
    p.add_argument(
        "--scratch",
        default=DEFAULT_SCRATCH,
        metavar="DIR",
        help="a directory on each node's own disk for the workers' files and Dask's spill "
        "files, expanded by the job's shell (default: the job's $TMPDIR, else /tmp)",
    )
    p.add_argument(
        "--print-script",
        action="store_true",
        help="print the script each job runs (the scheduler's address as tcp://SCHEDULER:PORT) "
        "and exit, submitting nothing",
    )
    p.set_defaults(func=cmd_cluster)


def cmd_cluster(args: argparse.Namespace) -> None:
    """Print the job script, or submit the jobs and keep their scheduler until stopped."""
    from experiments.batches.jobqueue import ClusterError, JobSpec, job_script, serve

    try:
        spec = JobSpec(
            system=args.system,
            cores=args.cores,
            memory=args.memory,
            walltime=args.walltime,
            queue=args.queue,
            account=args.account,
            interface=args.interface,
            scratch=args.scratch,
        )
        if args.print_script:
            print(job_script(spec), end="")
        else:
            serve(spec, args.jobs, lambda line: print(line, flush=True))
    except ClusterError as exc:
        raise UsageError(str(exc)) from None
