"""`playroom rl-compare`: Model Babbling's trials against the SAC + HER runs of the same grasps,
seeds, worlds and movements, tested over agents (experiments/report/rl_comparison.py,
rl_page.py). Reads files only: it needs no RL library."""

from __future__ import annotations

import argparse
import shlex

from experiments.cli.args import UsageError, study_reference_option


def add_parsers(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "rl-compare",
        help="Model Babbling against SAC + HER on the same test, paired by seed",
        description="A batch of Model Babbling trials (`playroom batch`) and the SAC + HER runs "
        "of the same batch config (`playroom rl-baseline --config`): for each grasp, each "
        "learner's competence per ring, strategies, what moved the goal toy in ring 1 and its "
        "words, one value per agent, with 95%% t intervals; SAC + HER's minus Model Babbling's "
        "paired by seed (paired t), Holm's correction over every test; the study's own measure "
        "of each learner beside an untrained agent's. Writes rl-compare.md, .csv, .json and "
        ".png into --out (docs/rl-baseline.md).",
    )
    p.add_argument("model_babbling", metavar="MB_DIR", help="the Model Babbling batch")
    p.add_argument("sac_her", metavar="SAC_DIR", help="the runs of `playroom rl-baseline --config`")
    p.add_argument("--out", required=True, help="where to write the page's files")
    study_reference_option(p)
    p.set_defaults(func=cmd_rl_compare)


def cmd_rl_compare(args: argparse.Namespace) -> None:
    """The page (experiments/report/rl_page.py), printed and written."""
    from experiments.analysis.results import ReportError
    from experiments.cli.report_commands import study_reference
    from experiments.report.rl_page import write_rl_compare

    command = shlex.join(["playroom", "rl-compare", args.model_babbling, args.sac_her])
    command += f" --out {shlex.quote(args.out)}"
    try:
        measures = study_reference(args, [args.model_babbling])["measures"]
        page = write_rl_compare(
            args.model_babbling, args.sac_her, args.out, command, measures.study_numbers
        )
    except ReportError as exc:
        raise UsageError(str(exc)) from None
    print(page.read_text(), end="")
    print(f"written: {page}, rl-compare.csv, rl-compare.json, rl-compare.png")
