"""The rows of a comparison page's table of differences that a document quotes, as Markdown,
from the page's summary.json (its `tests`: the page's table as it shows it), so that a table
copied into docs/ is regenerated from the files by one command:

    python -m experiments.report.summary_rows SUMMARY_JSON [PREFIX ...]

A row is kept when its measure starts with one of the PREFIXes (all rows without any); the
pooled second lines (└ ... pooled ...) are kept only where their own measure is listed."""

from __future__ import annotations

import argparse
import json
from pathlib import Path


def markdown_rows(summary: dict, prefixes: list[str]) -> str:
    """The page's table (its header, then the rows whose measure starts with a prefix)."""
    tests = summary.get("tests")
    if not tests:
        raise ValueError("this summary.json holds no table of differences (not a comparison's)")

    def cells(row: list) -> str:
        return "| " + " | ".join(str(c).replace("|", "/") for c in row) + " |"

    kept = [r for r in tests["rows"] if not prefixes or str(r[0]).startswith(tuple(prefixes))]
    lines = [cells(tests["columns"]), "|---" * len(tests["columns"]) + "|"]
    return "\n".join(lines + [cells(r) for r in kept]) + "\n"


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("summary", type=Path, help="a comparison page's summary.json")
    parser.add_argument("prefixes", nargs="*", help="the measures' first words to keep")
    args = parser.parse_args(argv)
    print(markdown_rows(json.loads(args.summary.read_text()), args.prefixes), end="")


if __name__ == "__main__":
    main()
