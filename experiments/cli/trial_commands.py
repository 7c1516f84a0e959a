"""`playroom random`, `run` and `eval`: one room, one trial, one trial's evaluation.
Each command loads what it needs when it runs, so that building the parser loads no
simulator."""

from __future__ import annotations

import argparse
import os
import sys
from collections import Counter

import numpy as np

from experiments.cli.args import (
    RUN_DEFAULTS,
    UsageError,
    non_negative_int,
    percent,
    positive_int,
    run_default,
    set_option,
    voice_option,
)
from experiments.cli.overrides import merged, random_world
from experiments.trial_dir.eval_worlds import OWN, WORLD_NAMES
from learner.config import BABBLING_MODES
from models.presets import DEFAULT_PRESET, PRESETS
from sim.config import STICK_RETURNS
from sim.grasping.names import DEFAULT_GRASP, GRASPS


def add_parsers(sub: argparse._SubParsersAction) -> None:
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
    set_option(p, "world settings only (e.g. a rung of the contact ladder, docs/world.md)")
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
    voice_option(p, run_default("voice"))
    set_option(p, "with --resume: must equal the trial's own overrides")
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
        "--scenes-clear-of-stick",
        action="store_true",
        help="a proposed departure, never the default: place every test scene's toys clear of "
        "the stick at its start, as the physical backend's learning placements are (by default "
        "some ring-1 scenes start with a toy on the stick: docs/protocol.md D20); eval.json "
        "says so",
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
    from experiments.run.settings import TrialSettings, resume_settings
    from experiments.run.trial import run_trial
    from experiments.trial_dir import storage
    from experiments.trial_dir.errors import TrialError

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
    from experiments.measure.evaluation import EvaluationSettings
    from experiments.measure.trial_evaluation import evaluate_trial
    from experiments.trial_dir import storage
    from experiments.trial_dir.errors import TrialError
    from experiments.trial_dir.reading import open_for_reading

    try:
        summary = evaluate_trial(
            args.dir,
            EvaluationSettings(
                n_placements=args.placements, scenes_clear_of_stick=args.scenes_clear_of_stick
            ),
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
        folder = open_for_reading(args.dir).evaluation_elsewhere(tested["name"]).folder
        print(f"  written into {os.path.join(args.dir, folder.name)}")
    print(f"  {open_for_reading(args.dir).computed_on_line()}")
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
