"""Two rules crossed (`playroom factorial`): four batch directories (or groups), one per cell of a
2 x 2 design, each rule off or on, read as the contact ladder's rungs are
(experiments/report/ladder.py), and each rule's effect measured with the other rule off, with
it on, and on average (its main effect), and the two rules' interaction, every one a contrast
of the cells' values per seed, tested over the seeds every cell holds: the mean contrast with
its 95% interval, the paired t's p and the signed-rank p (experiments/analysis/step_split.py).

Cells, in this order: neither rule, the first alone, the second alone, both. For a seed s with
values x00, x10, x01, x11: the first rule's effect without the second x10 - x00, with it
x11 - x01, its main effect the mean of the two; the second's likewise; the interaction
(x11 - x01) - (x10 - x00), what the first rule's effect changes when the second is on (the
same as the second's change with the first). The family, declared before any value is read
(`CONTRASTS` x the ladder's headline measures), and Holm's correction over it for each kind of
p. Written: factorial.md, factorial.csv (every test), factorial-trials.csv (every trial's
values, ladder_data), factorial.json.
"""

from __future__ import annotations

import os
from pathlib import Path

import pandas as pd

from experiments.analysis import step_split
from experiments.analysis.results import ReportError, check_out_dir
from experiments.report import ladder, ladder_data
from experiments.report.ladder_page import completeness_lines, json_records, rungs_table
from experiments.report.pages import survive
from experiments.report.paired_text import cell_text, level_text
from experiments.trial_dir import provenance, storage

FILES = ("factorial.csv", "factorial-trials.csv", "factorial.json", "factorial.md")
# Each contrast: its name and its weights on the cells (neither, first, second, both).
CONTRASTS = {
    "first, second off": (-1.0, 1.0, 0.0, 0.0),
    "first, second on": (0.0, 0.0, -1.0, 1.0),
    "first, main effect": (-0.5, 0.5, -0.5, 0.5),
    "second, first off": (-1.0, 0.0, 1.0, 0.0),
    "second, first on": (0.0, -1.0, 0.0, 1.0),
    "second, main effect": (-0.5, -0.5, 0.5, 0.5),
    "interaction": (1.0, -1.0, -1.0, 1.0),
}


# What the seeds some cells hold beyond the common ones enter (the completeness verdict).
OTHER_SEEDS = "Every contrast is taken on the seeds every cell holds; the others enter none."


def contrast_tests(
    values: pd.DataFrame, cells: list[str], measures: list[ladder.Headline]
) -> pd.DataFrame:
    """One row per (measure, contrast) of the family, on the seeds every cell holds in its own
    world (a seed missing a value in a cell is left out of that measure's contrasts)."""
    seeds = ladder.common_seeds(values, cells)
    own = values[(values["tested"] == ladder.OWN) & values["seed"].isin(seeds)]
    rows = []
    for h in measures:
        table = own[own["key"] == h.key].pivot(index="seed", columns="rung", values="value")
        table = table.reindex(columns=cells)
        for name, weights in CONTRASTS.items():
            used = {c: w for c, w in zip(cells, weights, strict=True) if w}
            # NaN where a cell it weighs lacks the seed's value (then no pair: left out).
            contrast = table[list(used)].mul(pd.Series(used)).sum(axis=1, min_count=len(used))
            zero = pd.Series(0.0, index=table.index)
            rows.append({"key": h.key, "contrast": name} | step_split.paired_test(contrast, zero))
    return pd.DataFrame(rows)


def _named(contrast: str, factors: tuple[str, str]) -> str:
    first, second = factors
    return (
        contrast.replace("first", f"«{first}»")
        .replace("second", f"«{second}»")
        .replace("«", "")
        .replace("»", "")
    )


def markdown(
    command: str, cells: list[ladder.Rung], factors: tuple[str, str], read, tests, check
) -> str:
    names = [c.name for c in cells]
    here = provenance.describe(provenance.short_record(provenance.machine_record()))
    seeds = ladder.common_seeds(read.values, names)
    own = read.values[(read.values["tested"] == ladder.OWN) & read.values["seed"].isin(seeds)]
    means = own.groupby(["key", "rung"])["value"].mean()
    n = step_split.counts([tests])
    head = [*(f"{c} (mean)" for c in names), *(_named(c, factors) for c in CONTRASTS)]
    table = ["| measure | " + " | ".join(head) + " |", "|---" * (len(head) + 1) + "|"]
    for h in read.measures:
        kind = h.measure.kind
        row = [level_text(kind, means.get((h.key, c), float("nan"))) for c in names]
        mine = tests[tests["key"] == h.key].set_index("contrast")
        row += [cell_text(kind, dict(mine.loc[c])) for c in CONTRASTS]
        table.append(f"| {h.label} | " + " | ".join(row) + " |")
    differ = [r for r in tests.to_dict("records") if step_split.stars_differ(r)]
    label = {h.key: h.label for h in read.measures}
    lines = [
        f"# {factors[0]} x {factors[1]}",
        "",
        f"Written by `{command}`; statistics computed on {here}.",
        "",
        f"Cells: {names[0]} (neither rule), {names[1]} ({factors[0]} alone), {names[2]} "
        f"({factors[1]} alone), {names[3]} (both). Each contrast is computed per seed on the "
        f"{len(seeds)} seeds every cell holds, the agent the unit: mean [95% t interval], the "
        "paired t's two-sided p, the Wilcoxon signed-rank p (rank p), (seeds); * where it "
        "survives Holm's correction over the family for its kind of p. The interaction is "
        f"what {factors[0]}'s effect changes when {factors[1]} is on. Per-trial data: "
        "[factorial-trials.csv](factorial-trials.csv).",
        "",
        *rungs_table(cells, [], read.own, against_first=True),
        "",
        "## Each rule with the other off and on, main effects, interaction",
        "",
        *table,
        "",
        "## The family of tests",
        "",
        f"One family of {n['family']} tests ({len(CONTRASTS)} contrasts of each of "
        f"{len(read.measures)} measures), fixed by the cells and the measures before any value "
        f"was read; {n['made']} could be made. Holm's correction over them: {survive(n['t'])} "
        f"with the paired t, {n['rank']} with the signed-rank test.",
        "",
        "## Where the t and the signed-rank test disagree on a star",
        "",
        *(
            [f"- {label.get(r['key'], r['key'])}, {_named(r['contrast'], factors)}" for r in differ]
            or ["None."]
        ),
        "",
        "## Completeness",
        "",
        *completeness_lines(check, OTHER_SEEDS),
    ]
    return "\n".join(lines) + "\n"


def factorial_files(
    read: ladder.LadderRead, cells: list[ladder.Rung], factors: tuple[str, str], command: str
) -> dict[str, bytes]:
    """Every file (FILES) from the cells as `ladder.read_ladder` read them."""
    names = [c.name for c in cells]
    (tests,) = step_split.with_holm(contrast_tests(read.values, names, read.measures))
    check = ladder.completeness(read.values, names)
    keys = [h.key for h in read.measures]
    trials = ladder_data.trial_table(read.values, read.provenance, keys)
    record = {
        "command": command,
        "factors": list(factors),
        "cells": [{"name": c.name, "batch": str(c.batch_dir), "group": c.group} for c in cells],
        "contrasts": {k: list(v) for k, v in CONTRASTS.items()},
        "tests": json_records(tests),
        "completeness": json_records(check),
    }
    return {
        "factorial.csv": tests.to_csv(index=False).encode(),
        "factorial-trials.csv": trials.to_csv(index=False).encode(),
        "factorial.json": storage.json_bytes(record),
        "factorial.md": markdown(command, cells, factors, read, tests, check).encode(),
    }


def write_factorial(
    cells: list[ladder.Rung], factors: tuple[str, str], out_dir: str | os.PathLike, command: str
) -> Path:
    """Read the four cells, test and write (module docstring); nothing is written unless all
    of it is computed. ReportError (one line) unless there are four cells. The page's path."""
    if len(cells) != len(next(iter(CONTRASTS.values()))):
        raise ReportError(
            f"a 2 x 2 design has 4 cells (neither, the first rule, the second, both), not "
            f"{len(cells)}"
        )
    out = Path(out_dir)
    check_out_dir(out)
    read = ladder.read_ladder(cells)
    return storage.write_files(out, factorial_files(read, cells, factors, command))[-1]
