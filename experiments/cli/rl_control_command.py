"""`playroom rl-control`: the positive control of the RL baseline, SAC + HER with the settings
of experiments/baseline/control_settings.py on the hand and stick goals, its learning curves on
held-out goals as a table and a figure (experiments/baseline/control_run.py). Needs the `rl`
extra."""

from __future__ import annotations

import argparse
import shlex
import sys

from experiments.baseline.control_settings import (
    CONTROL,
    CONTROL_GOALS,
    EVAL_EVERY,
    EVAL_GOALS,
    FIRST_TEST_SEED,
    HELD_OUT,
    MOVEMENTS,
    SEEDS,
    SETTINGS_CHOICES,
    TORCH_THREADS,
)
from experiments.cli.args import UsageError, non_negative_int, positive_int
from sim.grasping.names import DEFAULT_GRASP, GRASPS

DESCRIPTION = (
    "The positive control of the RL baseline: stable-baselines3's SAC with its HerReplayBuffer, "
    "with the RL Zoo's FetchReach settings (docs/rl-baseline.md), trained on a goal "
    "environment of sim/envs with its defaults (the arm alone, one movement a goal, the sparse "
    "reward) for each goal and seed, and tested on held-out goals (drawn by the environment, "
    "never met at rest, the same for every run) before it moves and every --every movements, "
    "beside the nearest outcome among the movements it was given and random arm commands on "
    "the same goals. --settings defaults runs stable-baselines3's defaults instead; "
    "--test-goals validation tests on goals kept for checking settings, never the held-out "
    "ones. Writes OUT/rl-control.csv (goal, seed, learner, steps, success, "
    "critic_success, saturated), rl-control.json (settings, stable-baselines3's defaults, each "
    "run's seconds, libraries and machine) and rl-control.png; each run's curve is kept in "
    "OUT/runs/ when it ends, so that the same command run again skips the runs done. Needs the "
    "`rl` extra: make install-rl."
)


def add_parsers(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "rl-control",
        help="SAC + HER's learning curves on the hand and stick goals (needs the rl extra)",
        description=DESCRIPTION,
    )
    p.add_argument("--out", required=True, help="the directory of the runs and their curves")
    p.add_argument(
        "--goals",
        nargs="+",
        choices=CONTROL_GOALS,
        default=list(CONTROL_GOALS),
        help=f"the goals (default: {' '.join(CONTROL_GOALS)})",
    )
    p.add_argument(
        "--seeds", type=positive_int, default=SEEDS, help=f"how many seeds (default: {SEEDS})"
    )
    p.add_argument(
        "--first-seed",
        type=non_negative_int,
        default=0,
        metavar="S",
        help="seeds S to S+N-1 (default: 0)",
    )
    p.add_argument(
        "--settings",
        choices=SETTINGS_CHOICES,
        default=CONTROL,
        help="the learner's: the control's (docs/rl-baseline.md) or stable-baselines3's "
        f"defaults (default: {CONTROL})",
    )
    p.add_argument(
        "--test-goals",
        choices=tuple(FIRST_TEST_SEED),
        default=HELD_OUT,
        help="the goals tested on: the held-out ones, or the validation ones for checking "
        f"settings (default: {HELD_OUT})",
    )
    p.add_argument(
        "--movements",
        type=positive_int,
        default=MOVEMENTS,
        help=f"movements a run (default: {MOVEMENTS})",
    )
    p.add_argument(
        "--every",
        type=positive_int,
        default=EVAL_EVERY,
        help=f"movements between two tests; divides --movements (default: {EVAL_EVERY})",
    )
    p.add_argument(
        "--eval-goals",
        type=positive_int,
        default=EVAL_GOALS,
        help=f"held-out goals a test (default: {EVAL_GOALS})",
    )
    p.add_argument(
        "--grasp", choices=GRASPS, default=DEFAULT_GRASP, help=f"default: {DEFAULT_GRASP}"
    )
    p.add_argument(
        "--torch-threads",
        type=positive_int,
        default=TORCH_THREADS,
        metavar="N",
        help=f"torch's CPU threads (default: {TORCH_THREADS})",
    )
    p.add_argument("--quiet", action="store_true", help="no progress bar")
    p.set_defaults(func=cmd_rl_control)


def cmd_rl_control(args: argparse.Namespace) -> None:
    from experiments.baseline.control_run import run_control
    from experiments.baseline.control_settings import (
        NEAREST,
        RANDOM,
        TARGETS,
        ControlError,
        ControlSettings,
    )
    from experiments.report.rl_control_figure import control_png

    try:
        runs = [
            ControlSettings(
                goal,
                seed,
                args.movements,
                args.every,
                args.eval_goals,
                args.grasp,
                args.settings,
                args.test_goals,
            )  # fmt: skip
            for goal in dict.fromkeys(args.goals)
            for seed in range(args.first_seed, args.first_seed + args.seeds)
        ]
        actors = (runs[0].learner, NEAREST, RANDOM)
        command = ["playroom", "rl-control", "--out", args.out, "--goals", *args.goals]
        command += ["--seeds", str(args.seeds), "--first-seed", str(args.first_seed)]
        command += ["--settings", args.settings, "--test-goals", args.test_goals]
        command += ["--movements", str(args.movements)]
        command += ["--every", str(args.every), "--eval-goals", str(args.eval_goals)]
        command += ["--grasp", args.grasp, "--torch-threads", str(args.torch_threads)]
        table = run_control(
            args.out,
            runs,
            shlex.join(command),
            lambda rows: control_png(rows, actors, TARGETS),
            threads=args.torch_threads,
            progress=not args.quiet,
            notify=lambda line: print(f"playroom rl-control: {line}", file=sys.stderr, flush=True),
        )
    except ControlError as exc:
        raise UsageError(str(exc)) from None
    print(f"{table}: the curves of {len(runs)} runs (and rl-control.json, rl-control.png)")
    _print_final(table, actors[0])


def _print_final(table_path: object, learner: str) -> None:
    """Each goal's success at the last test, per seed, for the learner and the references."""
    import pandas as pd

    table = pd.read_csv(str(table_path))
    last = table[table["steps"] == table["steps"].max()]
    for (goal, actor), rows in last.groupby(["goal", "learner"], sort=False):
        values = ", ".join(f"{100 * v:.0f}%" for v in rows.sort_values("seed")["success"])
        mark = " (learner)" if actor == learner else ""
        print(f"  {goal}, {actor}{mark}: {values} (seeds {', '.join(map(str, rows['seed']))})")
