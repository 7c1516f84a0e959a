"""The `playroom` command line. Every way a command ends but success is one line on stderr
with an exit code: 2 for what the user asked (bad arguments, unusable directories), 1 for a
fault of the machine (disk full, read-only file system), 130 for Ctrl-C (SIGINT) and 143 for
SIGTERM, each line saying what was kept and how to resume (experiments/cli/faults.py)."""

from __future__ import annotations

import argparse
import sys
import textwrap

from experiments.batches.stored import stored_profiles
from experiments.bench.names import ON_REQUEST, SECTION_HELP, SECTION_NAMES
from experiments.cli import agent_measures_command, ladder_command, rl_command, rl_compare_command
from experiments.cli.args import (
    Parser,
    VersionAction,
    iteration_list,
    non_negative_int,
    positive_int,
    run_default,
    study_reference_option,
)
from experiments.cli.commands import (
    cmd_ablations,
    cmd_batch,
    cmd_bench,
    cmd_compare,
    cmd_eval,
    cmd_random,
    cmd_render,
    cmd_report,
    cmd_run,
    cmd_say,
    cmd_sounds,
    cmd_view,
    cmd_voice_data,
)
from experiments.cli.faults import run_command
from experiments.cli.overrides import dotted_setting
from experiments.eval_worlds import OWN, WORLD_NAMES
from learner.config import BABBLING_MODES
from models.presets import DEFAULT_PRESET, PRESETS
from models.tracts import DEFAULT_TRACT, TRACTS
from sim.config import STICK_RETURNS
from sim.grasping.names import DEFAULT_GRASP, GRASPS
from sim.vocal.config import DEFAULT_VOICE


def _set_option(p: argparse.ArgumentParser, what: str) -> None:
    p.add_argument(
        "--set",
        type=dotted_setting,
        action="append",
        metavar="SECTION.NAME=VALUE",
        help="change one setting of the world or learner (repeatable; VALUE read as JSON, else "
        f"a string), e.g. --set learner.exploration_sigma=0.05; {what}",
    )


def _voice_option(p: argparse.ArgumentParser, which: str, default: str | None = None) -> None:
    p.add_argument(
        "--voice",
        choices=TRACTS,
        default=default,
        help="the vocal tract: VocalTractLab (vtl) or the study's DIVA map (diva; its data "
        f"installed once with `playroom voice-data diva PATH`); {which}",
    )


def build_parser() -> argparse.ArgumentParser:
    parser = Parser(
        prog="playroom", description="A MuJoCo playroom for Model Babbling of tool use and speech."
    )
    parser.add_argument(
        "--version", action=VersionAction, help="the package's version and commit, then exit"
    )
    sub = parser.add_subparsers(dest="command", required=True, parser_class=Parser)

    p = sub.add_parser("random", help="act random arm commands and print what happened")
    p.add_argument("--grasp", choices=GRASPS, default=DEFAULT_GRASP, help="the grasp backend")
    p.add_argument("--iterations", type=positive_int, default=20, help="arm commands to play")
    p.add_argument("--seed", type=non_negative_int, default=0, help="of the room and commands")
    p.add_argument(
        "--preset",
        choices=PRESETS,
        default=DEFAULT_PRESET,
        help="the room's world: as the study's code behaved, or the project's "
        "(default: %(default)s)",
    )
    _set_option(p, "world settings only (e.g. a rung of the contact ladder, docs/world.md)")
    p.set_defaults(func=cmd_random)

    p = sub.add_parser("run", help="one trial of Model Babbling into a directory")
    # No argparse defaults: a setting left out is the default below for a new trial, and the
    # trial's own (config.json) with --resume, where a setting given must match it.
    p.add_argument("--grasp", choices=GRASPS, help="the grasp backend; " + run_default("grasp"))
    p.add_argument(
        "--iterations",
        type=positive_int,
        metavar="N",
        help="iterations of the trial; " + run_default("iterations", " (a larger one extends it)"),
    )
    p.add_argument(
        "--seed",
        type=non_negative_int,
        help="of every random draw of the trial; " + run_default("seed"),
    )
    p.add_argument("--out", required=True, help="the trial directory")
    p.add_argument(
        "--babbling",
        choices=BABBLING_MODES,
        help="which model to train next: at random, or by learning progress (active); "
        + run_default("babbling"),
    )
    p.add_argument(
        "--checkpoint-every",
        type=positive_int,
        metavar="K",
        help="iterations between checkpoints (a killed trial resumes from its last); "
        + run_default("checkpoint_every"),
    )
    p.add_argument(
        "--stick-return",
        choices=STICK_RETURNS,
        help="the experimenter returns a stick beyond reach, or never (the study); "
        + run_default("stick_return"),
    )
    p.add_argument(
        "--preset",
        choices=PRESETS,
        help="world and learner as the study's code behaved, or the project's earlier choices "
        "(docs/protocol.md §11); " + run_default("preset"),
    )
    _voice_option(p, run_default("voice"))
    _set_option(p, "with --resume: must equal the trial's own overrides")
    p.add_argument(
        "--resume", action="store_true", help="continue the trial in --out as configured"
    )
    p.add_argument("--quiet", action="store_true", help="no progress bar")
    p.set_defaults(func=cmd_run)

    p = sub.add_parser("eval", help="evaluate a trial: competence, strategies, vocal errors")
    p.add_argument("dir", help="a trial directory written by `playroom run`")
    p.add_argument(
        "--placements", type=positive_int, default=100, help="toy placements tested per ring"
    )
    p.add_argument(
        "--world",
        choices=WORLD_NAMES,
        default=OWN,
        help="the world the final agent is tested in: its own (eval.json in DIR), or another "
        "backend with the switches of the trial's preset, written into DIR/eval-in-WORLD/ "
        "(one equal to its own is its own; docs/usage.md)",
    )
    p.add_argument("--quiet", action="store_true", help="no progress bar")
    p.set_defaults(func=cmd_eval)

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
    _set_option(p, "merged into the batch's overrides")
    p.add_argument(
        "--quiet",
        action="store_true",
        help="no progress bar (the dashboard's link is still printed)",
    )
    p.set_defaults(func=cmd_batch)

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
    p.add_argument("--out", required=True, help="where to write ablations.md/.csv/.png")
    study_reference_option(p)
    p.set_defaults(func=cmd_ablations)

    ladder_command.add_parser(sub)
    rl_command.add_parser(sub)
    rl_compare_command.add_parser(sub)
    agent_measures_command.add_parsers(sub)

    p = sub.add_parser("render", help="an MP4 of a trial's iterations, with overlay and sound")
    p.add_argument("dir", nargs="?", help="a trial directory written by `playroom run`")
    p.add_argument("--out", required=True, help="the MP4 file to write")
    which = p.add_mutually_exclusive_group()
    which.add_argument(
        "--iterations",
        type=iteration_list,
        metavar="I,J,...",
        help="iterations of the trial to film (or --highlights); with --random: as many as given "
        "(default: 4)",
    )
    which.add_argument(
        "--highlights", action="store_true", help="film the first grasp, tool use, word, ..."
    )
    p.add_argument("--random", action="store_true", help="random commands in a new room")
    p.add_argument(
        "--grasp", choices=GRASPS, default=DEFAULT_GRASP, help="with --random: the grasp backend"
    )
    p.add_argument(
        "--seed", type=non_negative_int, default=0, help="with --random: of room and commands"
    )
    p.add_argument("--size", default="640x480", help="frame size WxH in pixels, even numbers")
    p.add_argument("--fps", type=float, default=50.0, help="frames per second of the video")
    p.add_argument(
        "--camera", choices=["top", "hand_view"], default="top", help="the MJCF camera to film"
    )
    _voice_option(
        p, f"with --random (a trial's is its own); default: {DEFAULT_TRACT}", default=DEFAULT_TRACT
    )
    p.set_defaults(func=cmd_render)

    p = sub.add_parser(
        "view", help="watch a trial replayed, or a random agent, live in MuJoCo's viewer"
    )
    p.add_argument("dir", nargs="?", help="a trial directory written by `playroom run`")
    p.add_argument("--random", action="store_true", help="random commands in a new room")
    p.add_argument(
        "--from",
        dest="start",
        type=non_negative_int,
        default=0,
        metavar="I",
        help="the trial's first iteration to show (the earlier ones are replayed unseen)",
    )
    p.add_argument("--iterations", type=positive_int, default=20, help="iterations to show")
    p.add_argument(
        "--grasp", choices=GRASPS, default=DEFAULT_GRASP, help="with --random: the grasp backend"
    )
    p.add_argument(
        "--seed", type=non_negative_int, default=0, help="with --random: of room and commands"
    )
    _voice_option(p, f"with --random; default: {DEFAULT_TRACT}", default=DEFAULT_TRACT)
    p.add_argument(
        "--pace", type=float, default=1.0, help="speed against real time (2: twice as fast)"
    )
    p.set_defaults(func=cmd_view)

    p = sub.add_parser("voice-data", help="install the data a vocal tract needs (DIVA's map)")
    p.add_argument("tract", choices=["diva"], help="the tract whose data it is")
    p.add_argument(
        "path",
        nargs="?",
        help="DIVA's diva_synth.mat (or divapy's fmfit_py.mat); left out: say what is installed",
    )
    p.set_defaults(func=cmd_voice_data)

    p = sub.add_parser(
        "sounds", help="random vocal commands against the words, in each vocal tract (Fig. 1b)"
    )
    p.add_argument(
        "--voice",
        nargs="+",
        choices=TRACTS,
        default=list(TRACTS),
        help=f"the tracts to compare (default: {' '.join(TRACTS)}; diva needs its data installed)",
    )
    p.add_argument(
        "--commands",
        type=positive_int,
        default=200,
        help="random commands (default: 200, the paper's)",
    )
    p.add_argument("--seed", type=non_negative_int, default=0, help="of the commands (default: 0)")
    p.set_defaults(func=cmd_sounds)

    p = sub.add_parser("say", help="write a word as audio (WAV), from the agent's voice")
    p.add_argument("word", choices=DEFAULT_VOICE.words, help="one of the caregiver's 6 words")
    p.add_argument("--out", required=True, help="the WAV file to write")
    p.set_defaults(func=cmd_say)

    p = sub.add_parser(
        "bench",
        help="speed figures, one `name: value unit` per line",
        description="Speed figures, one `name: value unit` per line; ratios are measured side "
        "by side in one run. Sections:\n"
        + "\n".join(
            textwrap.fill(text, 88, initial_indent=f"  {name:<10}", subsequent_indent=" " * 12)
            for name, text in SECTION_HELP.items()
        ),
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument(
        "section",
        nargs="*",
        help=f"sections to run, of {', '.join(SECTION_NAMES)} "
        f"(default: all but {', '.join(ON_REQUEST)})",
    )
    p.set_defaults(func=cmd_bench)
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
