"""The contact ladder's page (`playroom ladder NAME=DIR[:GROUP] ... --out DIR`): the tests of
experiments/report/ladder.py written as one unit into DIR: ladder.md (the tables), ladder.csv
(every test, unrounded), ladder.json (every trial's values, every test, the rungs and where
they were computed) and ladder.png (the waterfall, experiments/report/ladder_figure.py)."""

from __future__ import annotations

import math
import os
from itertools import pairwise
from pathlib import Path

import pandas as pd

from experiments import provenance, storage
from experiments.analysis.results import BatchResults, check_out_dir
from experiments.analysis.trial_tests import survives
from experiments.eval_worlds import READ_BY
from experiments.report import ladder
from experiments.report.ablations import describe_change
from experiments.report.figures import png_bytes
from experiments.report.ladder_figure import waterfall
from experiments.report.pages import machines_text, p_value, seeds_text

FILES = ("ladder.csv", "ladder.json", "ladder.png", "ladder.md")
HEAD = {k: k.removeprefix("competence_") for k in ladder.COMPETENCE}
WORLDS_TABLE_TITLE = (
    "Every rung's agents in each world (normalised competence, mean over the trials of the "
    "seeds every rung holds, trials in brackets):"
)
PART_TEXT = {
    "learned": "learned (both rungs' agents tested in the {world} world)",
    "worlds": "the test worlds (own against the {world} world, B's change minus A's)",
}


def signed_text(kind: str, x: float) -> str:
    if not math.isfinite(x):
        return "n/a"
    return (
        f"{100 * x:+.1f}"
        if kind == "share"
        else f"{x:+.3f}"
        if kind == "distance"
        else (f"{x:+.2f}" if kind == "ratio" else f"{x:+.1f}")
    )


def level_text(kind: str, x: float) -> str:
    return signed_text(kind, x).lstrip("+")


def _cell(kind: str, row: dict) -> str:
    """A difference as "+1.5 [-0.0, +3.0], p = 0.054 (32)", * where it survives Holm."""
    n = int(row["n"])
    if not math.isfinite(row["mean"]):
        return f"n/a ({n} pairs)"
    low, high = signed_text(kind, row["low"]), signed_text(kind, row["high"])
    text = f"{signed_text(kind, row['mean'])} [{low}, {high}]"
    if not math.isfinite(row["p"]):
        return f"{text}, untested: every pair equal ({n})"
    mark = " *" if survives(row["p_holm"]) else ""
    return f"{text}, {p_value(row['p'])}{mark} ({n})"


def _rows(table: pd.DataFrame, where: dict | None = None, **also: str) -> list[dict]:
    """The rows of `table` whose columns hold the values given, as dicts."""
    mask = pd.Series(True, index=table.index)
    for column, value in {**(where or {}), **also}.items():
        mask &= table[column] == value
    return [dict(r) for r in table[mask].to_dict("records")]


def _change(before: dict, config: dict) -> str:
    """What a rung changes from the one before, each world setting that its backend does not
    read said so: another backend's switch (experiments/eval_worlds.py READ_BY)."""
    grasp = config["trial"]["grasp"]
    others = {name for g, names in READ_BY.items() if g != grasp for name in names}
    unread = others - set(READ_BY.get(grasp, ()))
    parts = []
    for part in describe_change(before, config).split("; "):
        key = part.split(":", 1)[0]
        name = key.removeprefix("world.")
        inert = key.startswith("world.") and name in unread
        parts.append(f"{part} (not read by the {grasp} backend)" if inert else part)
    return "; ".join(parts)


def rungs_table(rungs: list[ladder.Rung], own: dict[str, BatchResults]) -> list[str]:
    lines = ["| rung | batch | changes from the rung before | trials (seeds) | computed on |"]
    lines.append("|---|---|---|---|---|")
    before = None
    for rung in rungs:
        results = own[rung.name]
        group = results.groups[0]
        config = results.configs[group]
        change = "(the first rung)" if before is None else _change(before, config)
        seeds = sorted(int(s) for s in results.trials["seed"])
        lines.append(
            f"| {rung.name} | {rung.batch_dir.name} ({group}) | {change} | "
            f"{len(seeds)} ({seeds_text(seeds)}) | {machines_text(results)} |"
        )
        before = config
    return lines


def steps_table(
    measures: list[ladder.Headline],
    steps: pd.DataFrame,
    levels: pd.DataFrame,
    order: list[str],
    beside: list[str],
) -> list[str]:
    """Rows: measures; columns: the first rung's mean, each step, the last rung's mean, the
    whole difference, the steps' sum, the whole on every seed and each rung beside."""
    head = [f"{order[0]} (mean)", *(f"{a} -> {b}" for a, b in pairwise(order))]
    head += [f"{order[-1]} (mean)", "whole (first to last)", "steps' sum (whole minus sum)"]
    if (steps["kind"] == ladder.WHOLE_ALL).any():
        head.append("whole, every seed of the first and last rungs")
    head += [f"{order[-1]} -> {r} (beside)" for r in beside]
    lines = ["| measure | " + " | ".join(head) + " |", "|---" * (len(head) + 1) + "|"]
    sums = {r["key"]: r for r in _rows(ladder.steps_sum(steps))}
    for h in measures:
        kind = h.measure.kind
        level = {r["rung"]: r["mean"] for r in _rows(levels, tested=ladder.OWN, key=h.key)}
        cells = [level_text(kind, level.get(order[0], math.nan))]
        cells += [_cell(kind, r) for r in _rows(steps, key=h.key, kind=ladder.STEP)]
        cells.append(level_text(kind, level.get(order[-1], math.nan)))
        cells += [_cell(kind, r) for r in _rows(steps, key=h.key, kind=ladder.WHOLE)]
        s = sums[h.key]
        inside = "within" if s["within"] else "outside"
        cells.append(
            f"{signed_text(kind, s['steps_sum'])} "
            f"({signed_text(kind, s['whole_minus_sum'])}; {inside} the whole's interval)"
        )
        for which in (ladder.WHOLE_ALL, ladder.BESIDE):
            cells += [_cell(kind, r) for r in _rows(steps, key=h.key, kind=which)]
        lines.append(f"| {h.label} | " + " | ".join(cells) + " |")
    return lines


def split_table(splits: pd.DataFrame, levels: pd.DataFrame) -> list[str]:
    """Each step's competence split in each test world; then every rung in every world."""
    if splits.empty:
        return ["No rung was tested in another world (`playroom eval DIR --world W`)."]
    keys = list(ladder.COMPETENCE)
    lines = ["| step | part | " + " | ".join(HEAD[k] for k in keys) + " |"]
    lines.append("|---" * (len(keys) + 2) + "|")
    seen = splits[["from", "to", "kind", "world", "part"]].drop_duplicates()
    for case in seen.to_dict("records"):
        by_key = {r["key"]: r for r in _rows(splits, case)}
        cells = [_cell("share", by_key[k]) if k in by_key else "" for k in keys]
        step = f"{case['from']} -> {case['to']}" + (
            " (whole)" if case["kind"] == ladder.WHOLE else ""
        )
        part = PART_TEXT[case["part"]].format(world=case["world"])
        lines.append(f"| {step} | {part} | " + " | ".join(cells) + " |")
    lines += ["", WORLDS_TABLE_TITLE]
    lines += ["", "| rung | tested in | " + " | ".join(HEAD[k] for k in keys) + " |"]
    lines.append("|---" * (len(keys) + 2) + "|")
    for case in levels[["rung", "tested"]].drop_duplicates().to_dict("records"):
        by_key = {r["key"]: r for r in _rows(levels, case)}
        cells = [
            f"{100 * by_key[k]['mean']:.1f} ({by_key[k]['n']})" if k in by_key else "" for k in keys
        ]
        lines.append(f"| {case['rung']} | {case['tested']} | " + " | ".join(cells) + " |")
    return lines


def markdown(command: str, rungs, beside, own, measures, steps, splits, levels, missing) -> str:
    order, others = [r.name for r in rungs], [r.name for r in beside]
    tests = pd.concat([steps, splits], ignore_index=True)
    made = int(tests["p"].notna().sum())
    kept = sum(survives(float(p)) for p in tests["p_holm"])
    here = provenance.describe(provenance.short_record(provenance.machine_record()))
    lines = [
        "# The contact ladder",
        "",
        f"Written by `{command}`; statistics computed on {here}.",
        "",
        f"{made} tests over trials (paired t over seeds, two-sided); {kept} survive Holm's "
        "correction over all of them at 0.05 (marked *). No test here pools tests or words "
        "across agents. Each cell: the mean over seeds of the later rung minus the earlier "
        "[95% interval], p, (pairs). Shares in percentage points.",
        "",
        *rungs_table([*rungs, *beside], own),
        "",
        "## Each rung's step",
        "",
        *steps_table(measures, steps, levels, order, others),
        "",
        "![waterfall](ladder.png)",
        "",
        "## Learned, or the test world? (cross-evaluation)",
        "",
        *split_table(splits, levels),
    ]
    if missing:
        lines += ["", "Not tested in another world:", "", *(f"- {m}" for m in missing)]
    return "\n".join(lines) + "\n"


def json_records(table: pd.DataFrame) -> list[dict]:
    """A table's rows for JSON: a value that is not finite (no test, no value) as null."""
    return [
        {k: (None if isinstance(v, float) and not math.isfinite(v) else v) for k, v in r.items()}
        for r in table.to_dict("records")
    ]


def write_ladder(
    rungs: list[ladder.Rung],
    beside: list[ladder.Rung],
    out_dir: str | os.PathLike,
    command: str,
) -> Path:
    """Read, test and write (module docstring); nothing is written unless all of it is
    computed. Returns the page's path."""
    out = Path(out_dir)
    check_out_dir(out)
    values, measures, own, missing = ladder.read_ladder(rungs, beside)
    order, others = [r.name for r in rungs], [r.name for r in beside]
    steps = ladder.step_tests(values, order, others, measures)
    splits = ladder.split_tests(values, order, others)
    steps, splits = ladder.with_holm(steps, splits)
    # The rungs' means on the seeds the steps pair, so that the first plus the steps is the last.
    common = ladder.common_seeds(values, order)
    levels = ladder.levels(values[values["seed"].isin(common) | values["rung"].isin(others)])
    page = markdown(command, rungs, beside, own, measures, steps, splits, levels, missing)
    record = {
        "command": command,
        "rungs": [{"name": r.name, "batch": str(r.batch_dir), "group": r.group} for r in rungs],
        "beside": [{"name": r.name, "batch": str(r.batch_dir), "group": r.group} for r in beside],
        "measures": {h.key: {"label": h.label, "kind": h.measure.kind} for h in measures},
        "values": json_records(values),
        "steps": json_records(steps),
        "splits": json_records(splits),
        "steps_sum": json_records(ladder.steps_sum(steps)),
        "levels": json_records(levels),
        "not_tested": missing,
    }
    tests = pd.concat([steps.assign(part="step"), splits], ignore_index=True)
    files = {
        "ladder.csv": tests.to_csv(index=False).encode(),
        "ladder.json": storage.json_bytes(record),
        "ladder.png": png_bytes(waterfall(measures, steps, levels, order)),
        "ladder.md": page.encode(),
    }
    return storage.write_files(out, files)[-1]
