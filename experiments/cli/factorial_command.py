"""`playroom factorial`: two rules crossed, four batch directories read as one page of tests
over trials (experiments/report/factorial.py)."""

from __future__ import annotations

import argparse
import shlex

from experiments.cli.args import UsageError
from experiments.cli.ladder_command import _rung


def add_parsers(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "factorial",
        help="two rules crossed (2 x 2 cells), each rule's effect and their interaction",
        description="Four cells of a 2 x 2 design, each a batch directory (DIR:GROUP for one "
        "group of a batch of both backends), in the order: neither rule, the first alone, the "
        "second alone, both. Per measure of the contact ladder: each rule's effect with the "
        "other off and on, its main effect and the interaction, each a contrast per seed with "
        "the paired t's and the signed-rank test's p, Holm's correction over the family. "
        "Writes factorial.md, factorial.csv, factorial-trials.csv and factorial.json into --out.",
    )
    p.add_argument(
        "cells",
        nargs="+",
        type=_rung,
        metavar="NAME=DIR[:GROUP]",
        help="the cells: neither rule, the first alone, the second alone, both",
    )
    p.add_argument(
        "--factors",
        nargs=2,
        required=True,
        metavar="RULE",
        help="the two rules' names, the first and the second",
    )
    p.add_argument("--out", required=True, help="where to write the page's files")
    p.set_defaults(func=cmd_factorial)


def cmd_factorial(args: argparse.Namespace) -> None:
    """The factorial's page (experiments/report/factorial.py)."""
    from experiments.analysis.results import ReportError
    from experiments.report.factorial import write_factorial

    cells = " ".join(
        shlex.quote(f"{r.name}={r.batch_dir}" + (f":{r.group}" if r.group else ""))
        for r in args.cells
    )
    factors = " ".join(shlex.quote(f) for f in args.factors)
    command = f"playroom factorial {cells} --factors {factors} --out {args.out}"
    try:
        page = write_factorial(args.cells, tuple(args.factors), args.out, command)
    except ReportError as exc:
        raise UsageError(str(exc)) from None
    print(page.read_text(), end="")
    print(f"written: {page}, factorial.csv, factorial-trials.csv, factorial.json")
