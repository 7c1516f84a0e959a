"""`playroom batch`: many trials on a Dask cluster, each run and evaluated."""

from __future__ import annotations

import argparse

from experiments.batches.cluster_settings import RETRIES, WORKER_WAIT_S
from experiments.batches.stored import stored_profiles
from experiments.cli.args import (
    UsageError,
    non_negative_int,
    percent,
    positive_int,
    set_option,
)
from experiments.cli.overrides import merged


def add_parsers(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("batch", help="many trials on a Dask cluster, each run and evaluated")
    which = p.add_mutually_exclusive_group(required=True)
    which.add_argument(
        "--profile",
        choices=stored_profiles(),
        metavar="NAME",
        help=f"a stored profile: {', '.join(stored_profiles())} (experiments/batches/profiles/)",
    )
    which.add_argument("--config", help="a JSON file of the same form as the profiles")
    p.add_argument("--out", required=True, help="the batch directory")
    p.add_argument(
        "--scheduler",
        metavar="tcp://HOST:PORT",
        help="a running Dask scheduler (default: a local cluster, its dashboard on a free port)",
    )
    p.add_argument("--workers", type=positive_int, help="local worker processes (default: cores)")
    p.add_argument(
        "--retries",
        type=non_negative_int,
        default=RETRIES,
        metavar="N",
        help="how many times a trial is run again, from its checkpoint, after its worker dies "
        "or a fault that may pass (a full disk); the scheduler's allowed failures for every "
        f"client (default: {RETRIES}, Dask's own)",
    )
    p.add_argument(
        "--worker-wait",
        type=positive_int,
        default=WORKER_WAIT_S,
        metavar="SECONDS",
        help="how long to wait for a first worker of the scheduler before giving up "
        f"(default: {WORKER_WAIT_S})",
    )
    set_option(p, "merged into the batch's overrides")
    p.add_argument(
        "--quiet",
        action="store_true",
        help="no progress bar (the dashboard's link is still printed)",
    )
    p.set_defaults(func=cmd_batch)


def cmd_batch(args: argparse.Namespace) -> None:
    """Many trials on Dask, each run and evaluated; reruns skip what is complete."""
    from experiments.batches.runner import run_batch
    from experiments.batches.spec import BatchError, load_spec, with_overrides

    try:
        spec = load_spec(args.profile, args.config)
        if args.set:
            try:
                spec = with_overrides(spec, merged(spec.overrides, args.set))
            except ValueError as exc:  # a --set given twice
                raise BatchError(str(exc)) from None
        results = run_batch(
            spec, args.out, scheduler=args.scheduler, n_workers=args.workers,
            progress=not args.quiet, retries=args.retries, worker_wait_s=args.worker_wait,
        )  # fmt: skip
    except BatchError as exc:
        raise UsageError(str(exc)) from None
    for name, summary in sorted(results.items()):
        c = summary["competence"]
        tested = "".join(
            f"; in the {world} world ring1 {percent(t['ring1'])}, all {percent(t['all'])}"
            for world, t in summary.get("eval_worlds", {}).items()
        )
        print(f"  {name}: competence ring1 {percent(c['ring1'])}, all {percent(c['all'])}{tested}")
    print(f"{args.out}: {len(spec.trials())} trials complete")
