"""`playroom bench`: speed figures, ratios measured side by side in one run."""

from __future__ import annotations

import argparse
import textwrap

from experiments.bench.names import ON_REQUEST, SECTION_HELP, SECTION_NAMES
from experiments.cli.args import (
    UsageError,
)


def add_parsers(sub: argparse._SubParsersAction) -> None:
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
