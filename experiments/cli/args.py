"""Argument types, shared options, errors and printed numbers of the `playroom` command line
(experiments/cli/main.py)."""

from __future__ import annotations

import argparse
from typing import Any, NoReturn

import numpy as np

from experiments.cli.overrides import dotted_setting
from learner.config import LearnerConfig
from models.presets import DEFAULT_PRESET
from models.tracts import DEFAULT_TRACT, TRACTS
from sim.config import DEFAULT_WORLD
from sim.grasping.names import DEFAULT_GRASP

# What `playroom run` does when a setting is left out of a new trial (a resumed one keeps its
# own: experiments/run/settings.py). TrialSettings' own defaults are those of short trials.
RUN_DEFAULTS: dict[str, Any] = {
    "grasp": DEFAULT_GRASP,
    "iterations": 80000,
    "seed": 0,
    "babbling": LearnerConfig.babbling,
    "checkpoint_every": 1000,
    "stick_return": DEFAULT_WORLD.stick_return,
    "preset": DEFAULT_PRESET,
    "voice": DEFAULT_TRACT,
}


def run_default(name: str, more: str = "") -> str:
    """Help of a `run` option: its default for a new trial (a resumed trial keeps its own)."""
    return f"default: {RUN_DEFAULTS[name]}; with --resume: the trial's own{more}"


class UsageError(Exception):
    """A problem with what the user asked for: printed as one line, exit code 2."""


def non_negative_int(text: str) -> int:
    value = int(text)
    if value < 0:
        raise argparse.ArgumentTypeError(f"must be >= 0, got {value}")
    return value


def positive_int(text: str) -> int:
    value = int(text)
    if value <= 0:
        raise argparse.ArgumentTypeError(f"must be > 0, got {value}")
    return value


def iteration_list(text: str) -> list[int]:
    try:
        values = [int(v) for v in text.split(",") if v.strip()]
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected I,J,... integers, got {text!r}") from None
    if not values:
        raise argparse.ArgumentTypeError("no iteration given")
    return values


class HelpFormatter(argparse.ArgumentDefaultsHelpFormatter):
    """argparse's help with each option's default at the end of its line, except where there
    is none to show (None, a flag's False) or the help already says it (a `run` option's
    default depends on --resume)."""

    def _get_help_string(self, action: argparse.Action) -> str | None:
        text = action.help or ""
        if (
            any(action.default is x for x in (None, False, argparse.SUPPRESS))  # 0 is shown
            or "default" in text
            or (not action.option_strings and action.nargs not in ("?", "*"))
        ):
            return text
        return f"{text} (default: %(default)s)"


class Parser(argparse.ArgumentParser):
    """argparse with the defaults in every help (`HelpFormatter`). Its own errors (a bad
    option) keep argparse's form: the command's usage line, then the message, exit code 2;
    a command's own errors (`UsageError`) are one line (experiments/cli/faults.py)."""

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        kwargs.setdefault("formatter_class", HelpFormatter)
        super().__init__(*args, **kwargs)


class VersionAction(argparse.Action):
    """`--version`: the package's version and, in a git checkout, its commit. Computed only
    when asked (git is not run for every command)."""

    def __init__(self, option_strings: list[str], dest: str, help: str | None = None) -> None:
        super().__init__(option_strings, dest, nargs=0, default=argparse.SUPPRESS, help=help)

    def __call__(self, parser: argparse.ArgumentParser, *args: Any) -> NoReturn:
        print(version_text())
        parser.exit()


def version_text() -> str:
    """'playroom 0.1.0 (commit ce04631+dirty)', or '(installed package)' outside a checkout."""
    from importlib.metadata import version

    from experiments.trial_dir.provenance import commit_text, source_record

    source = source_record()
    where = ("commit " if source.get("commit") else "") + commit_text(source)
    return f"playroom {version('playroom')} ({where})"


def study_reference_option(p: argparse.ArgumentParser) -> None:
    p.add_argument(
        "--study-reference-commands",
        type=positive_int,
        metavar="N",
        help="random commands per ring behind the study's own measure (default: the batch's "
        "study_reference_commands, which its profile sets: the study's 30000, 10000 placements "
        "x 3 toys, at the study's scale, fewer for smoke and demo)",
    )
    p.add_argument(
        "--workers",
        type=positive_int,
        metavar="N",
        help="processes playing the study's random reference when it is not kept yet "
        "(default: cores; the numbers do not depend on it)",
    )


def percent(fraction: float | None) -> str:
    """Competence as the report pages print it (experiments/report/pages.pct, one decimal):
    "-0.8%", "46.0%", "n/a" (also for None: eval.json's null for a number that is not finite).
    Kept here so that the CLI's summaries load no report code."""
    return "n/a" if fraction is None or not np.isfinite(fraction) else f"{100 * fraction:.1f}%"


def set_option(p: argparse.ArgumentParser, what: str) -> None:
    p.add_argument(
        "--set",
        type=dotted_setting,
        action="append",
        metavar="SECTION.NAME=VALUE",
        help="change one setting of the world or learner (repeatable; VALUE read as JSON, else "
        f"a string), e.g. --set learner.exploration_sigma=0.05; {what}",
    )


def voice_option(p: argparse.ArgumentParser, which: str, default: str | None = None) -> None:
    p.add_argument(
        "--voice",
        choices=TRACTS,
        default=default,
        help="the vocal tract: VocalTractLab (vtl) or the study's DIVA map (diva; its data "
        f"installed once with `playroom voice-data diva PATH`); {which}",
    )
