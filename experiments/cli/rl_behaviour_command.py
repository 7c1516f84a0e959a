"""`playroom rl-behaviour`: what the SAC + HER runs' toy policies do in the environments they
were trained in, against random actions there (experiments/baseline/behaviour.py). Needs the
`rl` extra."""

from __future__ import annotations

import argparse
from pathlib import Path

from experiments.cli.args import UsageError, positive_int

DEFAULT_EPISODES = 30


def add_parsers(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "rl-behaviour",
        help="what the SAC + HER policies do where they learned, beside random actions",
        description="For each run of `playroom rl-baseline` (a run's directory, or a folder of "
        "runs) and each of its toy policies, acting deterministically in the toy-goal "
        "environment it was trained in, and uniform random actions on the same episodes (the "
        "same rooms and goals): the share of movements that were the voice, that moved the "
        "goal toy and that reached the goal. Prints one line per toy and actor; --out writes "
        "them as CSV. Needs the rl extra (docs/rl-baseline.md).",
    )
    p.add_argument("runs", nargs="+", metavar="RUN", help="run directories, or folders of runs")
    p.add_argument(
        "--episodes",
        type=positive_int,
        default=DEFAULT_EPISODES,
        help=f"episodes per toy and actor (3 movements each; default: {DEFAULT_EPISODES})",
    )
    p.add_argument("--out", help="a CSV file for the table")
    p.set_defaults(func=cmd_rl_behaviour)


def _run_dirs(given: list[str]) -> list[Path]:
    from experiments.trial_dir.baseline_run import BASELINE_RUN_MARK, open_baseline_run

    def is_run(path: Path) -> bool:
        return open_baseline_run(path).is_run()

    dirs: list[Path] = []
    for name in given:
        path = Path(name)
        found = [path] if is_run(path) else sorted(p for p in path.glob("*") if is_run(p))
        if not found:
            raise UsageError(f"{name} holds no run of playroom rl-baseline ({BASELINE_RUN_MARK})")
        dirs += found
    return dirs


def cmd_rl_behaviour(args: argparse.Namespace) -> None:
    """The table, printed and written."""
    from experiments.baseline.behaviour import as_rows, run_behaviour
    from experiments.baseline.settings import BaselineError
    from experiments.baseline.training import rl_library
    from experiments.trial_dir import storage

    runs = _run_dirs(args.runs)  # what is asked for first, then whether it can be done
    try:
        rl_library()  # one line where the rl extra is missing
        rows = [b for run in runs for b in run_behaviour(run, args.episodes)]
    except (BaselineError, storage.CorruptFileError) as exc:
        raise UsageError(str(exc)) from None
    for b in rows:
        print(
            f"{b.run} toy{b.toy} {b.actor:>6}: {b.movements} movements, voice "
            f"{100 * b.voice:.1f}%, goal toy moved {100 * b.moved:.1f}%, goal reached "
            f"{100 * b.reached:.1f}%"
        )
    if args.out:
        import pandas as pd

        storage.write_text(Path(args.out), pd.DataFrame(as_rows(rows)).to_csv(index=False))
        print(f"written: {args.out}")
