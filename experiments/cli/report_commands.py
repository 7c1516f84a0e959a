"""`playroom report`, `compare` and `ablations`: the pages of batches, with the room measures
they are handed (the study's random reference, the stick's grasp rates)."""

from __future__ import annotations

import argparse

from experiments.cli.args import (
    UsageError,
    positive_int,
    study_reference_option,
)


def add_parsers(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("report", help="figures and report.html of a batch beside the paper")
    p.add_argument("dir", help="a batch directory of evaluated trials")
    p.add_argument("--out", help="where to write (default: DIR)")
    study_reference_option(p)
    p.set_defaults(func=cmd_report)

    p = sub.add_parser("compare", help="kinematic vs physical batches side by side")
    p.add_argument("dir_a", help="a batch directory (e.g. the kinematic one)")
    p.add_argument("dir_b", help="another batch directory, or DIR_A again if it holds both")
    p.add_argument("--out", required=True, help="where to write comparison.html")
    p.add_argument(
        "--grasp-rate-commands",
        type=positive_int,
        metavar="N",
        help="random arm commands played in each backend for the stick's grasp rates "
        "(default: the comparison's own, which the page states)",
    )
    study_reference_option(p)
    p.set_defaults(func=cmd_compare)

    p = sub.add_parser("ablations", help="batches changing a setting, against a baseline")
    p.add_argument("baseline", help="the baseline batch directory (e.g. the replication)")
    p.add_argument("batches", nargs="+", help="batch directories, each changing a setting")
    p.add_argument(
        "--out", required=True, help="where to write ablations.md/.csv/.png, ablations-trials.csv"
    )
    study_reference_option(p)
    p.set_defaults(func=cmd_ablations)


def cmd_report(args: argparse.Namespace) -> None:
    """Figures and report.html of a batch, its numbers beside the paper's."""
    from experiments.analysis.results import ReportError
    from experiments.report.batch_report import write_report

    try:
        print(write_report(args.dir, args.out, **study_reference(args, [args.dir])))
    except ReportError as exc:
        raise UsageError(str(exc)) from None


def cmd_compare(args: argparse.Namespace) -> None:
    """Two batches (or one batch of both backends, given twice) side by side."""
    from experiments.analysis.results import ReportError
    from experiments.report.comparison import write_comparison

    try:
        print(
            write_comparison(
                args.dir_a,
                args.dir_b,
                args.out,
                **study_reference(args, [args.dir_a, args.dir_b]),
                **_grasp_rate_commands(args),
            )
        )
    except ReportError as exc:
        raise UsageError(str(exc)) from None


def cmd_ablations(args: argparse.Namespace) -> None:
    """Batches that change a setting or two, against a baseline batch, paired by seed."""
    from experiments.analysis.results import ReportError
    from experiments.report import ablation_data
    from experiments.report.ablations import write_ablations

    try:
        dirs = [args.baseline, *args.batches]
        table = write_ablations(
            args.baseline, args.batches, args.out, **study_reference(args, dirs)
        )
    except ReportError as exc:
        raise UsageError(str(exc)) from None
    print(table.read_text(), end="")
    print(f"written: {table}, ablations.csv, {ablation_data.FILE}, ablations.png")


def _grasp_rate_commands(args: argparse.Namespace) -> dict:
    """The number of commands behind the comparison's grasp rates, if one was asked for."""
    n = args.grasp_rate_commands
    return {} if n is None else {"grasp_rate_commands": n}


def study_reference(args: argparse.Namespace, batch_dirs: list[str]) -> dict:
    """The room measures a report shows (measured here, by the measuring stage: a report
    builds no room), with the reference size asked for, else the one the batches record (their
    profile's), else the study's (experiments.analysis.study_summary), played on the processes
    asked for (--workers), else on every core."""
    from experiments.analysis.batch_record import RecordMismatch, recorded_reference_commands
    from experiments.measure.for_reports import room_measures

    try:
        n = args.study_reference_commands or recorded_reference_commands(batch_dirs)
    except RecordMismatch as exc:
        raise UsageError(str(exc)) from None
    workers = getattr(args, "workers", None)  # None: the machine's cores
    # The grasp rates play each backend in the world its trials ran in (stick.batch_worlds).
    if n is None:
        return {"measures": room_measures(workers=workers, batch_dirs=batch_dirs)}
    return {"measures": room_measures(n, workers=workers, batch_dirs=batch_dirs)}
