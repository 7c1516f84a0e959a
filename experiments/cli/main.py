"""The `playroom` command line. Every way a command ends but success is one line on stderr
with an exit code: 2 for what the user asked (bad arguments, unusable directories), 1 for a
fault of the machine (disk full, read-only file system), 130 for Ctrl-C (SIGINT) and 143 for
SIGTERM, each line saying what was kept and how to resume (experiments/cli/faults.py)."""

from __future__ import annotations

import argparse
import sys

from experiments.cli import (
    agent_measures_command,
    batch_command,
    bench_command,
    cluster_command,
    factorial_command,
    ladder_command,
    report_commands,
    rl_behaviour_command,
    rl_command,
    rl_compare_command,
    rl_control_command,
    rl_race_command,
    trial_commands,
    video_commands,
    voice_commands,
)
from experiments.cli.args import Parser, VersionAction
from experiments.cli.faults import run_command

# The commands' modules, in the order `playroom --help` lists them.
COMMAND_MODULES = (
    trial_commands,
    batch_command,
    cluster_command,
    report_commands,
    ladder_command,
    factorial_command,
    rl_command,
    rl_compare_command,
    rl_behaviour_command,
    rl_control_command,
    rl_race_command,
    agent_measures_command,
    video_commands,
    voice_commands,
    bench_command,
)


def build_parser() -> argparse.ArgumentParser:
    parser = Parser(
        prog="playroom", description="A MuJoCo playroom for Model Babbling of tool use and speech."
    )
    parser.add_argument(
        "--version", action=VersionAction, help="the package's version and commit, then exit"
    )
    sub = parser.add_subparsers(dest="command", required=True, parser_class=Parser)
    for module in COMMAND_MODULES:
        module.add_parsers(sub)
    return parser


# Commands that render choose an OpenGL backend themselves; the others load none.
RENDERING_COMMANDS = ("render", "bench", "view")


def _command_parser(parser: argparse.ArgumentParser, command: str) -> argparse.ArgumentParser:
    """The parser of one command (`playroom run`, ...)."""
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            return action.choices[command]
    return parser


def main(argv: list[str] | None = None) -> int:
    parser = build_parser()
    try:
        args, extra = parser.parse_known_args(argv)
        if extra:  # said by the command's own parser, with its usage line, not the top one's
            _command_parser(parser, args.command).error(
                f"unrecognized arguments: {' '.join(extra)}"
            )
    except SystemExit as exc:  # --help, --version, or argparse's own error (usage, exit 2)
        return exc.code if isinstance(exc.code, int) else 0
    if args.command not in RENDERING_COMMANDS:
        from experiments.video import gl

        try:
            gl.without_rendering()
        except gl.GLError as exc:  # the user's MUJOCO_GL names a library that cannot load
            print(f"playroom {args.command}: error: {exc}", file=sys.stderr)
            return 2
    return run_command(args, sys.argv[1:] if argv is None else list(argv))


if __name__ == "__main__":
    sys.exit(main())
