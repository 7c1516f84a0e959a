"""`playroom replay` and `playroom voice-memory`: experiments on the final agents of finished
trials (experiments/measure/replay.py, voice_memory.py), each a CSV of one row per test or
toy model, its summary printed per backend."""

from __future__ import annotations

import argparse
from pathlib import Path

from experiments.cli.args import UsageError, positive_int


def add_parsers(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "replay",
        help="replay the final agents' chosen movements where they were learned and in the test",
        description="For each ring-1 test where a finished trial's final agent chose the arm, "
        "replay the remembered movement in four scenes (alone, remembered, stick at start, the "
        "test's own) and how far the goal toy's outcome lands from the remembered one "
        "(experiments/measure/replay.py, docs/comparison.md section 4). Writes one row per "
        "(trial, test) into the CSV, prints each backend's medians and means, and with "
        "--figure draws them (distance to the remembered outcome per scene; error by the toy's "
        "shift).",
    )
    p.add_argument("batch", type=Path, help="a batch directory (one or both backends)")
    p.add_argument(
        "--trials",
        type=positive_int,
        default=8,
        help="finished trials per backend, the first by name (default: 8)",
    )
    p.add_argument("--out", type=Path, required=True, help="the CSV to write")
    p.add_argument("--figure", type=Path, help="also the figure, as this PNG")
    p.set_defaults(func=cmd_replay)
    p = sub.add_parser(
        "voice-memory",
        help="what the final agents' voice -> toy models remember",
        description="For each voice -> toy model of each trial's final agent: its rows, the "
        "share of their commands the caregiver recognises as the toy's name, as another word "
        "or as no word, and the share of rows whose toy was only nudged "
        "(experiments/measure/voice_memory.py, docs/comparison.md section 5). Writes one row "
        "per (trial, toy) into the CSV and prints each backend's means.",
    )
    p.add_argument("trials", nargs="+", type=Path, help="trial directories")
    p.add_argument("--out", type=Path, required=True, help="the CSV to write")
    p.set_defaults(func=cmd_voice_memory)


def _checked_out(path: Path) -> None:
    """UsageError before any work where the CSV (or figure) cannot be written there."""
    from experiments.trial_dir import storage

    if path.is_dir():
        raise UsageError(f"--out {path} is a directory: give a file name")
    try:
        storage.check_writable(path.parent)
    except OSError as exc:
        raise UsageError(f"cannot write into {path.parent}: {storage.reason(exc)}") from None


def cmd_replay(args: argparse.Namespace) -> None:
    """The replay test of a batch's finished trials (module docstring)."""
    from experiments.measure.replay import replay_batch, summaries
    from experiments.trial_dir import storage
    from experiments.trial_dir.errors import TrialError

    for path in (args.out, args.figure):
        if path is not None:
            _checked_out(path)
    try:
        table = replay_batch(args.batch, args.trials)
    except (TrialError, storage.CorruptFileError) as exc:
        raise UsageError(str(exc)) from None
    storage.write_bytes(args.out, table.to_csv(index=False).encode())
    medians, means = summaries(table)
    print(f"medians per backend:\n{medians}\nmeans per backend:\n{means}")
    if args.figure is not None:
        from experiments.report.figures import png_bytes
        from experiments.report.mechanism_figures import replay_figure

        storage.write_bytes(args.figure, png_bytes(replay_figure(table)))
    print(f"written: {args.out}" + (f", {args.figure}" if args.figure else ""))


def cmd_voice_memory(args: argparse.Namespace) -> None:
    """What the trials' voice -> toy models remember (module docstring)."""
    from experiments.measure.voice_memory import trials_table
    from experiments.trial_dir import storage
    from experiments.trial_dir.errors import TrialError

    _checked_out(args.out)
    try:
        table = trials_table(args.trials)
    except (TrialError, storage.CorruptFileError) as exc:
        raise UsageError(str(exc)) from None
    storage.write_bytes(args.out, table.to_csv(index=False).encode())
    columns = ["rows", "name", "other_word", "no_word", "nudged"]
    print(table.groupby("grasp")[columns].mean().round(3).to_string())
    print(f"trials per backend: {table.groupby('grasp')['trial'].nunique().to_dict()}")
    print(f"written: {args.out}")
