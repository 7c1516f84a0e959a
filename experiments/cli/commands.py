"""The commands of `playroom` (experiments/cli/main.py parses the command line): each loads
what it needs when it runs, so that building the parser loads no simulator."""

from __future__ import annotations

import argparse
import os
import sys
from collections import Counter

import numpy as np

from experiments.cli.args import RUN_DEFAULTS, UsageError
from experiments.cli.overrides import merged, random_world


def percent(fraction: float | None) -> str:
    """Competence as the report pages print it (experiments/report/pages.pct, one decimal):
    "-0.8%", "46.0%", "n/a" (also for None: eval.json's null for a number that is not finite).
    Kept here so that the CLI's summaries load no report code."""
    return "n/a" if fraction is None or not np.isfinite(fraction) else f"{100 * fraction:.1f}%"


def cmd_random(args: argparse.Namespace) -> None:
    """Random arm commands in one backend, with a summary of what happened."""
    from models.layout import ARM_DIM
    from sim import Playroom
    from sim import events as ev

    try:
        world = random_world(args.grasp, args.preset, args.set)
    except ValueError as exc:
        raise UsageError(str(exc)) from None
    room = Playroom(grasp=args.grasp, seed=args.seed, config=world)
    rng = np.random.default_rng(args.seed)
    counts: Counter[str] = Counter()
    commands_with: Counter[str] = Counter()  # commands in which each kind of event happened
    print(f"{args.iterations} random arm commands, {args.grasp} grasping, seed {args.seed}")
    for i in range(args.iterations):
        feedback = room.act_arm(rng.uniform(-1.0, 1.0, ARM_DIM))
        commands_with.update(set(feedback.kinds()))
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
    rates = (ev.STICK_GRASPED, ev.TOY_GRASPED, ev.TOY_CAUGHT)
    print(
        "  share of commands: "
        + ", ".join(f"{kind} {percent(commands_with[kind] / args.iterations)}" for kind in rates)
    )


def cmd_run(args: argparse.Namespace) -> None:
    """One trial of Model Babbling, written to a directory that survives being killed."""
    from experiments import storage
    from experiments.run.settings import TrialSettings, resume_settings
    from experiments.run.trial import run_trial
    from experiments.run.trial_files import TrialError

    # Left out: None. A new trial takes the defaults, a resumed one its own settings.
    given = {name: getattr(args, name) for name in RUN_DEFAULTS if getattr(args, name) is not None}
    if args.set:
        try:
            given["overrides"] = merged({}, args.set)
        except ValueError as exc:
            raise UsageError(str(exc)) from None
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
    from experiments.file_names import eval_world_dir
    from experiments.measure.evaluation import EvaluationSettings
    from experiments.measure.trial_evaluation import evaluate_trial
    from experiments.provenance import computed_on_line
    from experiments.run.trial_files import TrialError

    try:
        summary = evaluate_trial(
            args.dir,
            EvaluationSettings(n_placements=args.placements),
            progress=not args.quiet,
            notify=lambda line: print(f"playroom eval: {line}", file=sys.stderr, flush=True),
            world=args.world,
        )
    except (TrialError, storage.CorruptFileError) as exc:
        raise UsageError(str(exc)) from None
    c, v = summary["competence"], summary["vocal"]
    tested = summary.get("eval_world")
    where = "" if tested is None else f", tested in the {tested['name']} world ({_differs(tested)})"
    print(
        f"{args.dir}: {summary['grasp']}, seed {summary['seed']}, "
        f"{summary['evaluated_at_iteration']} iterations{where}"
    )
    if tested is not None:
        print(f"  written into {os.path.join(args.dir, eval_world_dir(tested['name']))}")
    print(f"  {computed_on_line(args.dir)}")
    print(
        "  normalised competence (0% = random agent, 100% = perfect): "
        + ", ".join(f"{k} {percent(val)}" for k, val in c.items())
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


def _differs(tested: dict) -> str:
    """How an eval world differs from the trial's own, for a line: "grasp kinematic -> physical"."""
    return "; ".join(
        f"{key.split('.')[-1]} {own} -> {test}"
        for key, (own, test) in tested["differs_from_own"].items()
    )


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
            progress=not args.quiet,
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


def cmd_render(args: argparse.Namespace) -> None:
    """An MP4 of a trial's iterations (replayed exactly), or of random commands."""
    from experiments.video import gl

    try:
        gl.for_rendering()  # before anything imports mujoco
    except gl.GLError as exc:
        raise UsageError(str(exc)) from None
    from experiments import storage
    from experiments.run.trial_files import TrialError
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
    from experiments.report.ablations import write_ablations

    try:
        dirs = [args.baseline, *args.batches]
        table = write_ablations(
            args.baseline, args.batches, args.out, **study_reference(args, dirs)
        )
    except ReportError as exc:
        raise UsageError(str(exc)) from None
    print(table.read_text(), end="")
    print(f"written: {table}, {table.with_name('ablations.csv').name}, ablations.png")


def cmd_say(args: argparse.Namespace) -> None:
    """A word as audio, from the voice parameters found to produce it."""
    from pathlib import Path

    from sim.vocal.audio import write_wav
    from sim.vocal.config import DEFAULT_VOICE
    from sim.vocal.vtl.productions import stored_distances, synthesise_word

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
    from experiments.bench.names import ON_REQUEST
    from experiments.bench.sections import SECTIONS, run_bench

    unknown = [s for s in args.section if s not in SECTIONS]
    if unknown:
        raise UsageError(f"unknown bench section(s) {unknown}: choose from {sorted(SECTIONS)}")
    if render_skipped:
        sections = [s for s in SECTIONS if s != "render" and s not in ON_REQUEST]
    run_bench(sections)


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


def cmd_voice_data(args: argparse.Namespace) -> None:
    """Check the user's DIVA file and install its map, or say what is installed."""
    from sim.vocal.diva.data import (
        DivaDataError,
        DivaDataMissing,
        cache_path,
        install,
        installed_fit,
    )

    if args.path is None:
        try:
            installed_fit()
        except (DivaDataMissing, DivaDataError) as exc:
            raise UsageError(str(exc)) from None
        print(f"DIVA's map (the study's) is installed in {cache_path()}")
        return
    try:
        where, what = install(args.path)
    except DivaDataError as exc:
        raise UsageError(str(exc)) from None
    print(f"{args.path}: {what}; its map is installed in {where} (`--voice diva` uses it)")


def cmd_sounds(args: argparse.Namespace) -> None:
    """Random vocal commands against the words, one column per tract (the paper's Fig. 1b)."""
    from experiments.measure.random_sounds import random_sound_table

    tracts = tuple(dict.fromkeys(args.voice))  # in the order given, each once
    table = random_sound_table(tracts, args.commands, args.seed, progress=True)
    print(
        f"{args.commands} random vocal commands (seed {args.seed}, the study preset's DMP); "
        "distances in the 10D sound space, recognised below 0.4"
    )
    print(table.T.to_string(float_format=lambda x: f"{x:.3f}"))
