"""`playroom rl-baseline`: SAC with hindsight relabelling (stable-baselines3's defaults) trained
on the toy goals, then tested with the project's measure as a trial's final agent is
(experiments/baseline/). Needs the `rl` extra."""

from __future__ import annotations

import argparse
import shlex
import sys
from typing import TYPE_CHECKING

from experiments.baseline.settings import EVAL_PLACEMENTS, TORCH_THREADS
from experiments.cli.args import UsageError, non_negative_int, positive_int
from models.presets import DEFAULT_PRESET, PRESETS
from models.tracts import DEFAULT_TRACT, TRACTS
from sim.grasping.names import DEFAULT_GRASP, GRASPS

if TYPE_CHECKING:
    from experiments.baseline.settings import BaselineSettings

DESCRIPTION = (
    "Train stable-baselines3's SAC with its HerReplayBuffer, every default kept, on the toy-goal "
    "environments of sim/envs (one policy per toy, the steps split equally), in the world of "
    "`playroom run --grasp G --seed S`, then test the policies with the project's competence "
    "measure exactly as that trial's final agent is tested (same placements, goals, random "
    "agent and errors; and the study's tests), and write eval.json and its tables as "
    "`playroom eval` does. One step is one movement of the arm or the voice (one environment "
    "step), as one Model Babbling iteration is: --steps N gives SAC the movements of a trial of "
    "N iterations. With --config, the baseline of every trial of a batch config (its grasps, "
    "seeds, iterations and placements), side by side. A stopped run resumes when the same "
    "command is run again; a finished one is refused (with --config: skipped), and so is a "
    "directory of other settings. Needs "
    "the `rl` extra: make install-rl. docs/rl-baseline.md has the protocol."
)


def add_parsers(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "rl-baseline",
        help="SAC + HER on the toy goals, tested as a trial's final agent (needs the rl extra)",
        description=DESCRIPTION,
    )
    p.add_argument("--out", required=True, help="the run's directory (with --config: the runs')")
    p.add_argument(
        "--steps",
        type=positive_int,
        metavar="N",
        help="movements in all (one step = one movement = one Model Babbling iteration), split "
        "equally over the three toys' policies; required without --config",
    )
    # No argparse defaults: with --config these are the config's, and one given is refused.
    p.add_argument("--grasp", choices=GRASPS, help=f"the grasp backend (default: {DEFAULT_GRASP})")
    p.add_argument(
        "--seed",
        type=non_negative_int,
        help="of SAC, its episodes' rooms and the trial whose room it is tested in (default: 0)",
    )
    p.add_argument(
        "--preset", choices=PRESETS, help=f"the world's preset (default: {DEFAULT_PRESET})"
    )
    p.add_argument(
        "--voice", choices=TRACTS, help=f"the vocal tract, vtl or diva (default: {DEFAULT_TRACT})"
    )
    p.add_argument(
        "--placements",
        type=positive_int,
        help=f"toy placements tested per ring (default: {EVAL_PLACEMENTS}, the study's)",
    )
    p.add_argument(
        "--torch-threads",
        type=positive_int,
        default=TORCH_THREADS,
        metavar="N",
        help="torch's CPU threads per run (small networks: runs side by side use the cores better)",
    )
    p.add_argument(
        "--config",
        metavar="FILE",
        help="a batch config (as `playroom batch --config`): the baseline of each of its trials "
        "into OUT/GRASP-sac-her-seedNNNN/; then --steps, --grasp, --seed, --preset, --voice and "
        "--placements are the config's",
    )
    p.add_argument("--workers", type=positive_int, help="with --config: processes (default: cores)")
    p.add_argument("--quiet", action="store_true", help="no progress bar")
    p.set_defaults(func=cmd_rl_baseline)


SINGLE_ONLY = ("steps", "grasp", "seed", "preset", "voice", "placements")


def cmd_rl_baseline(args: argparse.Namespace) -> None:
    from experiments.baseline.settings import BaselineError, BaselineSettings

    try:
        if args.config is not None:
            command = ["playroom", "rl-baseline", "--config", args.config, "--out", args.out]
            _batch(args, shlex.join(command))
            return
        if args.workers is not None:
            raise UsageError("--workers is for --config (runs side by side)")
        if args.steps is None:
            raise UsageError("--steps N is required (movements in all), or --config FILE")
        given = {
            name: getattr(args, option)
            for name, option in (
                ("grasp", "grasp"),
                ("seed", "seed"),
                ("preset", "preset"),
                ("voice", "voice"),
                ("eval_placements", "placements"),
            )
            if getattr(args, option) is not None
        }
        settings = BaselineSettings(steps=args.steps, torch_threads=args.torch_threads, **given)
        # The command that makes this run again, every setting spelled out.
        command = ["playroom", "rl-baseline", "--steps", str(settings.steps)]
        command += ["--grasp", settings.grasp, "--seed", str(settings.seed)]
        command += ["--preset", settings.preset, "--voice", settings.voice]
        command += ["--placements", str(settings.eval_placements)]
        command += ["--torch-threads", str(settings.torch_threads), "--out", args.out]
        _single(args, settings, shlex.join(command))
    except BaselineError as exc:
        raise UsageError(str(exc)) from None


def _single(args: argparse.Namespace, settings: BaselineSettings, command: str) -> None:
    from experiments.baseline.run import run_baseline
    from experiments.cli.args import percent

    summary = run_baseline(
        args.out,
        settings,
        command,
        progress=not args.quiet,
        notify=lambda line: print(f"playroom rl-baseline: {line}", file=sys.stderr, flush=True),
    )
    print(
        f"{args.out}: SAC + HER, {settings.steps} movements ({settings.grasp}, seed "
        f"{settings.seed}), tested on {settings.eval_placements} placements per ring"
    )
    print(
        "  normalised competence (0% = random agent, 100% = perfect): "
        + ", ".join(f"{k} {percent(v)}" for k, v in summary["competence"].items())
    )
    for ring, shares in summary["strategy_share"].items():
        print(f"  strategies {ring}: " + ", ".join(f"{k} {v:.0%}" for k, v in shares.items()))


def _batch(args: argparse.Namespace, command: str) -> None:
    from experiments.baseline.many import run_batch_baselines

    given = [f"--{n}" for n in SINGLE_ONLY if getattr(args, n) is not None]
    if given:
        raise UsageError(f"{', '.join(given)}: with --config the batch config's own are used")
    done, skipped = run_batch_baselines(
        args.config,
        args.out,
        command,
        workers=args.workers,
        progress=not args.quiet,
        torch_threads=args.torch_threads,
    )
    print(f"{args.out}: {done} baselines run, {skipped} found finished")
