"""The `playroom` command line. Every way a command ends but success is one line on stderr
with an exit code: 2 for what the user asked (bad arguments, unusable directories), 1 for a
fault of the machine (disk full, read-only file system), 130 for Ctrl-C (SIGINT) and 143 for
SIGTERM, each line saying what was kept and how to resume (experiments/cli/faults.py)."""

from __future__ import annotations

import argparse
import os
import sys
from collections import Counter

import numpy as np

from experiments.batches.stored import stored_profiles
from experiments.cli.args import (
    RUN_DEFAULTS,
    Parser,
    UsageError,
    iteration_list,
    non_negative_int,
    positive_int,
    run_default,
)
from experiments.cli.faults import run_command
from learner.config import BABBLING_MODES
from models.presets import PRESETS
from sim.config import STICK_RETURNS
from sim.grasping.names import DEFAULT_GRASP, GRASPS


def cmd_random(args: argparse.Namespace) -> None:
    """Random arm commands in one backend, with a summary of what happened."""
    from models.layout import ARM_DIM
    from sim import Playroom

    room = Playroom(grasp=args.grasp, seed=args.seed)
    rng = np.random.default_rng(args.seed)
    counts: Counter[str] = Counter()
    print(f"{args.iterations} random arm commands, {args.grasp} grasping, seed {args.seed}")
    for i in range(args.iterations):
        feedback = room.act_arm(rng.uniform(-1.0, 1.0, ARM_DIM))
        for e in feedback.events:
            counts[f"{e.kind}" + (f" by {e.by}" if e.by else "")] += 1
        if feedback.events:
            said = ", ".join(
                f"{e.kind}({e.obj or ''}{'' if e.by in (None, 'hand', 'stick') else ' ' + e.by})"
                f"@{e.step}"
                for e in feedback.events
            )
            print(f"  iteration {i:3d}: {said}")
    print("  totals: " + ", ".join(f"{k}: {v}" for k, v in sorted(counts.items())))


def cmd_run(args: argparse.Namespace) -> None:
    """One trial of Model Babbling, written to a directory that survives being killed."""
    from experiments import storage
    from experiments.run.settings import TrialSettings, resume_settings
    from experiments.run.trial import run_trial
    from experiments.run.trial_files import TrialError

    # Options left out are None: a new trial takes the documented defaults, a resumed one
    # its own settings, which those given must match.
    given = {name: getattr(args, name) for name in RUN_DEFAULTS if getattr(args, name) is not None}
    try:
        if args.resume:
            settings = resume_settings(args.out, given)
        else:
            settings = TrialSettings(**{**RUN_DEFAULTS, **given})
        trial = run_trial(
            args.out,
            settings,
            resume=args.resume,
            progress=not args.quiet,
            notify=lambda line: print(f"playroom run: {line}", file=sys.stderr, flush=True),
        )
    except (TrialError, storage.CorruptFileError) as exc:
        raise UsageError(str(exc)) from None
    c = trial.counts
    print(
        f"{args.out}: {trial.iteration} iterations ({settings.grasp}, seed {settings.seed}); "
        f"tool uses {c['tool_uses']}, words recognised {c['words_recognised']}, "
        f"stick returns {c['stick_returns']}, diverged {c['diverged']}"
    )


def cmd_eval(args: argparse.Namespace) -> None:
    """Competence, strategies and vocal accuracy of a trial's final state."""
    from experiments import storage
    from experiments.measure.evaluation import EvaluationSettings
    from experiments.measure.trial_evaluation import evaluate_trial
    from experiments.provenance import computed_on_line
    from experiments.run.trial_files import TrialError

    try:
        summary = evaluate_trial(
            args.dir, EvaluationSettings(n_placements=args.placements), progress=not args.quiet
        )
    except (TrialError, storage.CorruptFileError) as exc:
        raise UsageError(str(exc)) from None
    c, v = summary["competence"], summary["vocal"]
    print(
        f"{args.dir}: {summary['grasp']}, seed {summary['seed']}, "
        f"{summary['evaluated_at_iteration']} iterations"
    )
    print(f"  {computed_on_line(args.dir)}")
    print(
        "  normalised competence (0 = random agent, 1 = perfect): "
        + ", ".join(f"{k} {val:+.2f}" for k, val in c.items())
    )
    for ring, shares in summary["strategy_share"].items():
        print(f"  strategies {ring}: " + ", ".join(f"{k} {v:.0%}" for k, v in shares.items()))
    print(
        f"  words below 0.4: {v['share_below_threshold']:.0%}; median best distance: names "
        f"{v['median_names']:.2f}, distractors {v['median_distractors']:.2f}"
    )
    # The study pooled its runs per pixel before normalising: one trial has no such number.
    print(
        "  the study's tests: study-tests.parquet (its measure pools trials per pixel: "
        "`playroom report` of the batch computes it, as the study computed it)"
    )


def cmd_batch(args: argparse.Namespace) -> None:
    """Many trials on Dask, each run and evaluated; reruns skip what is complete."""
    from experiments.batches.runner import run_batch
    from experiments.batches.spec import BatchError, load_spec

    try:
        spec = load_spec(args.profile, args.config)
        results = run_batch(spec, args.out, scheduler=args.scheduler, n_workers=args.workers)
    except BatchError as exc:
        raise UsageError(str(exc)) from None
    for name, summary in sorted(results.items()):
        c = summary["competence"]
        print(f"  {name}: competence ring1 {c['ring1']:+.2f}, all {c['all']:+.2f}")
    print(f"{args.out}: {len(spec.trials())} trials complete")


def cmd_render(args: argparse.Namespace) -> None:
    """An MP4 of a trial's iterations (replayed exactly), or of random commands."""
    from experiments.video import gl

    try:
        gl.for_rendering()  # before anything imports mujoco
    except gl.GLError as exc:
        raise UsageError(str(exc)) from None
    from experiments.video.encoding import RenderError
    from experiments.video.episodes import render_random
    from experiments.video.replay import ReplayError, render_trial
    from sim.dmp import voice_trajectory
    from sim.vocal.audio import synthesise
    from sim.vocal.produce import synthesise_word

    try:
        if args.random:
            if args.dir is not None:
                raise UsageError("give either a trial directory or --random, not both")
            count = len(args.iterations) if args.iterations else 4
            path = render_random(
                args.grasp, args.seed, args.out, iterations=count, size=args.size,
                fps=args.fps, camera=args.camera,
                voice_audio=lambda m: synthesise(voice_trajectory(m)),
                word_audio=synthesise_word,
            )  # fmt: skip
            print(path)
            return
        if args.dir is None:
            raise UsageError("give a trial directory, or --random")
        path, replayed = render_trial(
            args.dir, args.out, iterations=args.iterations, use_highlights=args.highlights,
            size=args.size, fps=args.fps, camera=args.camera,
        )  # fmt: skip
    except (ValueError, RenderError, ReplayError) as exc:
        raise UsageError(str(exc)) from None
    for r in replayed:
        verdict = "events as logged" if r.matches else "DIFFERS from the log"
        print(f"  iteration {r.iteration}: replayed {verdict}")
        if not r.matches:
            diff = {k: (r.logged.get(k), v) for k, v in r.replayed.items() if r.logged.get(k) != v}
            print(f"    logged vs replayed: {diff}")
    print(path)


def cmd_report(args: argparse.Namespace) -> None:
    """Figures and report.html of a batch, its numbers beside the paper's."""
    from experiments.analysis.results import ReportError
    from experiments.report.batch_report import write_report

    try:
        print(write_report(args.dir, args.out, **_study_reference(args)))
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
                **_study_reference(args),
            )
        )
    except ReportError as exc:
        raise UsageError(str(exc)) from None


def cmd_ablations(args: argparse.Namespace) -> None:
    """Batches that change a setting or two, against a baseline batch, paired by seed."""
    from experiments.analysis.results import ReportError
    from experiments.report.ablations import write_ablations

    try:
        table = write_ablations(args.baseline, args.batches, args.out, **_study_reference(args))
    except ReportError as exc:
        raise UsageError(str(exc)) from None
    print(table.read_text(), end="")
    print(f"written: {table}, {table.with_name('ablations.csv').name}, ablations.png")


def cmd_say(args: argparse.Namespace) -> None:
    """A word as audio, from the voice parameters found to produce it."""
    from pathlib import Path

    from sim.vocal.audio import write_wav
    from sim.vocal.config import DEFAULT_VOICE
    from sim.vocal.produce import stored_distances, synthesise_word

    if args.word not in DEFAULT_VOICE.words:
        raise UsageError(f"unknown word {args.word!r}: one of {', '.join(DEFAULT_VOICE.words)}")
    out = Path(args.out)
    if not out.parent.is_dir() or not os.access(out.parent, os.W_OK):
        raise UsageError(f"cannot write {out}: {out.parent} is not a writable directory")
    waveform, rate = synthesise_word(args.word)
    write_wav(out, waveform, rate)
    distance = stored_distances()[args.word]
    print(f"{out}: /{args.word}/, {len(waveform) / rate:.2f} s; its sound is {distance:.3f} from "
          "the perfect word (recognised below 0.4)")  # fmt: skip


def cmd_bench(args: argparse.Namespace) -> None:
    from experiments.video import gl

    sections = args.section or None
    render_skipped = False
    if sections is None or "render" in sections:
        try:
            gl.for_rendering()  # before anything imports mujoco
        except gl.GLError as exc:
            if sections is not None:
                raise UsageError(str(exc)) from None
            print(f"render: skipped ({exc})", flush=True)
            render_skipped = True
    else:
        gl.without_rendering()
    from experiments.bench.sections import SECTIONS, run_bench

    unknown = [s for s in args.section if s not in SECTIONS]
    if unknown:
        raise UsageError(f"unknown bench section(s) {unknown}: choose from {sorted(SECTIONS)}")
    if render_skipped:
        sections = [s for s in SECTIONS if s != "render"]
    run_bench(sections)


def _study_reference_option(p: argparse.ArgumentParser) -> None:
    p.add_argument(
        "--study-reference-commands",
        type=positive_int,
        metavar="N",
        help="random commands per ring behind the study's own measure (default: the study's, "
        "10000 placements x 3 toys)",
    )


def _study_reference(args: argparse.Namespace) -> dict:
    """The room measures a report shows (measured here, by the measuring stage: a report
    builds no room), with the reference size asked for, if any (the default is the study's,
    experiments.analysis.study_summary)."""
    from experiments.measure.for_reports import room_measures

    n = args.study_reference_commands
    return {"measures": room_measures() if n is None else room_measures(n)}


def build_parser() -> argparse.ArgumentParser:
    parser = Parser(
        prog="playroom", description="A MuJoCo playroom for Model Babbling of tool use and speech."
    )
    sub = parser.add_subparsers(dest="command", required=True, parser_class=Parser)

    p = sub.add_parser("random", help="act random arm commands and print what happened")
    p.add_argument("--grasp", choices=GRASPS, default=DEFAULT_GRASP)
    p.add_argument("--iterations", type=positive_int, default=20)
    p.add_argument("--seed", type=non_negative_int, default=0)
    p.set_defaults(func=cmd_random)

    p = sub.add_parser("run", help="one trial of Model Babbling into a directory")
    # No argparse defaults: a setting left out is the default below for a new trial, and the
    # trial's own (config.json) with --resume, where a setting given must match it.
    p.add_argument("--grasp", choices=GRASPS, help=run_default("grasp"))
    p.add_argument(
        "--iterations",
        type=positive_int,
        help=run_default("iterations", " (a larger number extends it)"),
    )
    p.add_argument("--seed", type=non_negative_int, help=run_default("seed"))
    p.add_argument("--out", required=True, help="the trial directory")
    p.add_argument("--babbling", choices=BABBLING_MODES, help=run_default("babbling"))
    p.add_argument(
        "--checkpoint-every", type=positive_int, metavar="K", help=run_default("checkpoint_every")
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
    p.add_argument(
        "--resume", action="store_true", help="continue the trial in --out as configured"
    )
    p.add_argument("--quiet", action="store_true", help="no progress bar")
    p.set_defaults(func=cmd_run)

    p = sub.add_parser("eval", help="evaluate a trial: competence, strategies, vocal errors")
    p.add_argument("dir", help="a trial directory written by `playroom run`")
    p.add_argument("--placements", type=positive_int, default=100, help="per ring")
    p.add_argument("--quiet", action="store_true", help="no progress bar")
    p.set_defaults(func=cmd_eval)

    p = sub.add_parser("batch", help="many trials on a Dask cluster, each run and evaluated")
    which = p.add_mutually_exclusive_group(required=True)
    which.add_argument("--profile", help=f"a stored profile: {', '.join(stored_profiles())}")
    which.add_argument("--config", help="a JSON file of the same form as the profiles")
    p.add_argument("--out", required=True, help="the batch directory")
    p.add_argument("--scheduler", help="tcp://HOST:PORT of a running Dask scheduler")
    p.add_argument("--workers", type=positive_int, help="local worker processes (default: cores)")
    p.set_defaults(func=cmd_batch)

    p = sub.add_parser("report", help="figures and report.html of a batch beside the paper")
    p.add_argument("dir", help="a batch directory of evaluated trials")
    p.add_argument("--out", help="where to write (default: DIR)")
    _study_reference_option(p)
    p.set_defaults(func=cmd_report)

    p = sub.add_parser("compare", help="kinematic vs physical batches side by side")
    p.add_argument("dir_a", help="a batch directory (e.g. the kinematic one)")
    p.add_argument("dir_b", help="another batch directory, or DIR_A again if it holds both")
    p.add_argument("--out", required=True, help="where to write comparison.html")
    _study_reference_option(p)
    p.set_defaults(func=cmd_compare)

    p = sub.add_parser("ablations", help="batches changing a setting, against a baseline")
    p.add_argument("baseline", help="the baseline batch directory (e.g. the replication)")
    p.add_argument("batches", nargs="+", help="batch directories, each changing a setting")
    p.add_argument("--out", required=True, help="where to write ablations.md/.csv/.png")
    _study_reference_option(p)
    p.set_defaults(func=cmd_ablations)

    p = sub.add_parser("render", help="an MP4 of a trial's iterations, with overlay and sound")
    p.add_argument("dir", nargs="?", help="a trial directory written by `playroom run`")
    p.add_argument("--out", required=True, help="the MP4 file to write")
    which = p.add_mutually_exclusive_group()
    which.add_argument("--iterations", type=iteration_list, help="I,J,...: iterations to film")
    which.add_argument("--highlights", action="store_true", help="first grasp, tool use, ...")
    p.add_argument("--random", action="store_true", help="random commands in a new room")
    p.add_argument("--grasp", choices=GRASPS, default=DEFAULT_GRASP)
    p.add_argument("--seed", type=non_negative_int, default=0)
    p.add_argument("--size", default="640x480", help="WxH, even numbers")
    p.add_argument("--fps", type=float, default=50.0)
    p.add_argument("--camera", choices=["top", "hand_view"], default="top")
    p.set_defaults(func=cmd_render)

    p = sub.add_parser("say", help="write a word as audio (WAV), from the agent's voice")
    p.add_argument("word", help="one of the 6 words, e.g. oey")
    p.add_argument("--out", required=True, help="the WAV file to write")
    p.set_defaults(func=cmd_say)

    p = sub.add_parser("bench", help="speed figures, one `name: value unit` per line")
    p.add_argument("section", nargs="*", help="sections to run (default: all)")
    p.set_defaults(func=cmd_bench)
    return parser


# Commands that render choose an OpenGL backend themselves; the others load none.
RENDERING_COMMANDS = ("render", "bench")


def main(argv: list[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    if args.command not in RENDERING_COMMANDS:
        from experiments.video import gl

        gl.without_rendering()
    return run_command(args, sys.argv[1:] if argv is None else list(argv))


if __name__ == "__main__":
    sys.exit(main())
