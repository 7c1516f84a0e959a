"""`playroom ladder`: the contact ladder's rungs read as one page of tests over trials
(experiments/report/ladder.py, ladder_page.py)."""

from __future__ import annotations

import argparse
import shlex

from experiments.cli.args import UsageError


def _rung(text: str):
    from experiments.report.ladder import parse_rung

    try:
        return parse_rung(text)
    except ValueError as exc:
        raise argparse.ArgumentTypeError(str(exc)) from None


def add_parsers(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "ladder",
        help="rungs from one world to another, each step paired by seed",
        description="Rungs in ladder order, each a batch directory (DIR:GROUP for one group of "
        "a batch of both backends, e.g. comparison-diva:kinematic), one rule changed "
        "per rung: each step's difference per measure (the rule's effect given the rules "
        "before it), paired by seed, with the paired t's and the signed-rank test's p, the "
        "whole difference, and where the rungs' agents were tested in both worlds "
        "(`playroom eval DIR --world W`) each step with both rungs' agents tested in one "
        "world and their own worlds against it; Holm's correction over the page's one family "
        "of tests; a check that every rung holds every seed and world. Writes ladder.md, "
        "ladder.csv (every test), ladder-trials.csv (every trial's values in every world, "
        "with the machine and commit that computed it), ladder.json and ladder.png into --out.",
    )
    p.add_argument(
        "rungs",
        nargs="+",
        type=_rung,
        metavar="NAME=DIR[:GROUP]",
        help="the rungs in ladder order, from the first world to the last",
    )
    p.add_argument(
        "--beside",
        nargs="*",
        default=[],
        type=_rung,
        metavar="NAME=DIR[:GROUP]",
        help="rungs set against the last rung only (e.g. settling, after the physical backend)",
    )
    p.add_argument("--out", required=True, help="where to write the ladder's files")
    p.set_defaults(func=cmd_ladder)


def cmd_ladder(args: argparse.Namespace) -> None:
    """The ladder's page (experiments/report/ladder_page.py)."""
    from experiments.analysis.results import ReportError
    from experiments.report.ladder_page import write_ladder

    command = "playroom ladder " + " ".join(
        shlex.quote(f"{r.name}={r.batch_dir}" + (f":{r.group}" if r.group else ""))
        for r in args.rungs
    )
    if args.beside:
        command += " --beside " + " ".join(
            shlex.quote(f"{r.name}={r.batch_dir}" + (f":{r.group}" if r.group else ""))
            for r in args.beside
        )
    try:
        page = write_ladder(args.rungs, args.beside, args.out, command + f" --out {args.out}")
    except ReportError as exc:
        raise UsageError(str(exc)) from None
    print(page.read_text(), end="")
    print(f"written: {page}, ladder.csv, ladder-trials.csv, ladder.json, ladder.png")
