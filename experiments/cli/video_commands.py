"""`playroom render` and `view`: a trial's iterations or random commands filmed (EGL) or
shown live; each chooses its OpenGL backend before anything imports MuJoCo."""

from __future__ import annotations

import argparse

from experiments.cli.args import (
    UsageError,
    iteration_list,
    non_negative_int,
    positive_int,
    voice_option,
)
from models.tracts import DEFAULT_TRACT
from sim.grasping.names import DEFAULT_GRASP, GRASPS


def add_parsers(sub: argparse._SubParsersAction) -> None:
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
    voice_option(
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
    voice_option(p, f"with --random; default: {DEFAULT_TRACT}", default=DEFAULT_TRACT)
    p.add_argument(
        "--pace", type=float, default=1.0, help="speed against real time (2: twice as fast)"
    )
    p.set_defaults(func=cmd_view)


def cmd_render(args: argparse.Namespace) -> None:
    """An MP4 of a trial's iterations (replayed exactly), or of random commands."""
    from experiments.video import gl

    try:
        gl.for_rendering()  # before anything imports mujoco
    except gl.GLError as exc:
        raise UsageError(str(exc)) from None
    from experiments.trial_dir import storage
    from experiments.trial_dir.errors import TrialError
    from experiments.video.encoding import RenderError
    from experiments.video.episodes import render_random
    from experiments.video.replay import ReplayError, render_trial

    try:
        if args.random:
            if args.dir is not None:
                raise UsageError("give either a trial directory or --random, not both")
            count = len(args.iterations) if args.iterations else 4
            path = render_random(
                args.grasp, args.seed, args.out, iterations=count, size=args.size,
                fps=args.fps, camera=args.camera, voice=args.voice, sound=True, progress=True,
            )  # fmt: skip
            print(path)
            return
        if args.dir is None:
            raise UsageError("give a trial directory, or --random")
        path, replayed = render_trial(
            args.dir, args.out, iterations=args.iterations, use_highlights=args.highlights,
            size=args.size, fps=args.fps, camera=args.camera,
        )  # fmt: skip
    except (ValueError, RenderError, ReplayError, TrialError, storage.CorruptFileError) as exc:
        # A trial whose files are damaged, foreign or missing, or whose config makes no room.
        raise UsageError(" ".join(str(exc).split())) from None
    for r in replayed:
        verdict = "events as logged" if r.matches else "DIFFERS from the log"
        print(f"  iteration {r.iteration}: replayed {verdict}")
        if not r.matches:
            diff = {k: (r.logged.get(k), v) for k, v in r.replayed.items() if r.logged.get(k) != v}
            print(f"    logged vs replayed: {diff}")
    print(path)


def cmd_view(args: argparse.Namespace) -> None:
    """A trial replayed, or random commands, live in MuJoCo's viewer (needs a display)."""
    from experiments.video import gl
    from experiments.video.viewer import ViewError, display_missing

    missing = display_missing()
    if missing is not None:
        raise UsageError(missing)
    if (args.dir is None) == (not args.random):
        raise UsageError("give a trial directory or --random (one of the two)")
    if not args.pace > 0:
        raise UsageError(f"--pace must be > 0, got {args.pace}")
    try:
        gl.for_viewing()  # before anything imports mujoco
    except gl.GLError as exc:
        raise UsageError(str(exc)) from None
    from experiments.video.viewer import view_random, view_trial

    try:
        if args.random:
            shown = view_random(args.grasp, args.seed, args.iterations, args.voice, args.pace)
        else:
            shown = view_trial(args.dir, args.start, args.iterations, args.pace)
    except ViewError as exc:
        raise UsageError(str(exc)) from None
    print(f"{shown} iterations shown")
