"""`playroom rl-race`: Model Babbling against SAC + HER (stable-baselines3's defaults, and the
positive control's settings), one goal-conditioned policy for the three toys, the same movements,
learning curves on the same held-out toy goals (experiments/baseline/race_run.py). Needs the `rl`
extra."""

from __future__ import annotations

import argparse
import os
import shlex

from experiments.baseline.control_settings import TORCH_THREADS
from experiments.baseline.race_settings import EVAL_EVERY, EVAL_GOALS, LEARNERS, RACE_CONFIG
from experiments.cli.args import UsageError, positive_int
from sim.grasping.names import GRASPS

DESCRIPTION = (
    "The race of docs/rl-race.md: for every trial of a batch config (default: "
    f"{RACE_CONFIG}; its grasps, seeds, movements, babbling and world), Model Babbling's trial "
    "and one goal-conditioned SAC + HER policy of the three toys (PlayroomToysGoal-v1: the arm "
    "alone, one movement a goal) with stable-baselines3's defaults and with the positive "
    "control's settings, each given the trial's movements and tested every --every on the same "
    "held-out toy goals (drawn by the environment, never met at rest) as Model Babbling, beside "
    "random arm commands (the chance level); success near, far and in all. Writes "
    "OUT/rl-race.csv (learner, grasp, seed, steps, ring, goals, success), "
    "rl-race-claims.csv (each learner beside Model Babbling, paired by seed: Wilcoxon's "
    "signed-rank test; a difference is claimed only where it rejects), rl-race.png and "
    "rl-race.json; each run's curve is kept in OUT/runs/ when it ends and Model Babbling's "
    "tests at each budget, so that the same command run again goes on where it stopped. "
    "--seeds, --iterations and --grasps make a smaller race of the same form. Needs the `rl` "
    "extra: make install-rl."
)


def add_parsers(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "rl-race",
        help="Model Babbling against SAC + HER on the toys' goals (needs the rl extra)",
        description=DESCRIPTION,
    )
    p.add_argument("--out", required=True, help="the directory of the runs and their curves")
    p.add_argument(
        "--config", default=str(RACE_CONFIG), help=f"a batch config (default: {RACE_CONFIG})"
    )
    p.add_argument(
        "--learners",
        nargs="+",
        choices=LEARNERS,
        default=list(LEARNERS),
        help=f"default: {' '.join(LEARNERS)}",
    )
    p.add_argument("--seeds", type=positive_int, help="the config's first N seeds (default: all)")
    p.add_argument("--iterations", type=positive_int, help="movements a run (default: config's)")
    p.add_argument("--grasps", nargs="+", choices=GRASPS, help="default: the config's")
    p.add_argument(
        "--every",
        type=positive_int,
        default=EVAL_EVERY,
        help=f"movements between two tests; divides the movements (default: {EVAL_EVERY})",
    )
    p.add_argument(
        "--eval-goals",
        type=positive_int,
        default=EVAL_GOALS,
        help=f"held-out goals a test (default: {EVAL_GOALS})",
    )
    p.add_argument("--workers", type=positive_int, help="runs side by side (default: the cores)")
    p.add_argument(
        "--torch-threads",
        type=positive_int,
        default=TORCH_THREADS,
        metavar="N",
        help=f"torch's CPU threads a run (default: {TORCH_THREADS})",
    )
    p.set_defaults(func=cmd_rl_race)
    lookup = sub.add_parser(
        "rl-race-lookup",
        help="a finished race's Model Babbling asked by where the toy starts and ends",
        description=LOOKUP_DESCRIPTION,
    )
    lookup.add_argument("race", help="a race's directory (playroom rl-race --out)")
    lookup.set_defaults(func=cmd_rl_race_lookup)


LOOKUP_DESCRIPTION = (
    "How much of Model Babbling's race score is the question it is asked "
    "(experiments/baseline/race_lookup.py): every Model Babbling trial of a finished race, at "
    "its final movements, tested again on the race's held-out goals with its memory looked up "
    "by the toy's start and end (the experience nearest in context, start and end, replayed) "
    "instead of by the study's straight goal trajectory. Writes RACE/rl-race-lookup.csv (grasp, "
    "seed, steps, question, ring, goals, success) and rl-race-lookup-summary.csv (means over "
    "the trials and the Wilcoxon signed-rank p of the difference), and prints the summary."
)


def cmd_rl_race(args: argparse.Namespace) -> None:
    from experiments.baseline.race_run import CLAIMS, run_race
    from experiments.baseline.race_settings import RaceError, race_runs
    from experiments.report.rl_race_figure import race_png

    try:
        learners = list(dict.fromkeys(args.learners))
        runs = race_runs(
            args.config,
            learners,
            args.seeds,
            args.iterations,
            args.grasps,
            args.every,
            args.eval_goals,
        )
        command = ["playroom", "rl-race", "--out", args.out, "--config", args.config]
        command += ["--learners", *args.learners]
        for flag, value in (("--seeds", args.seeds), ("--iterations", args.iterations)):
            command += [] if value is None else [flag, str(value)]
        command += [] if args.grasps is None else ["--grasps", *args.grasps]
        command += ["--every", str(args.every), "--eval-goals", str(args.eval_goals)]
        table = run_race(
            args.out,
            runs,
            shlex.join(command),
            lambda rows: race_png(rows, learners),
            workers=args.workers or os.cpu_count() or 1,
            threads=args.torch_threads,
        )
    except RaceError as exc:
        raise UsageError(str(exc)) from None
    print(f"{table}: the curves of {len(runs)} runs (and {CLAIMS}, rl-race.png, rl-race.json)")


def cmd_rl_race_lookup(args: argparse.Namespace) -> None:
    from experiments.baseline.race_lookup import LOOKUP_TABLE, lookup_summary, race_lookup
    from experiments.baseline.race_settings import RaceError

    try:
        table = race_lookup(args.race)
    except RaceError as exc:
        raise UsageError(str(exc)) from None
    print(lookup_summary(table).to_string(index=False, float_format="%.4g"))
    trials = len(table[["grasp", "seed"]].drop_duplicates())
    print(f"{os.path.join(args.race, LOOKUP_TABLE)}: {trials} trials asked both ways")
