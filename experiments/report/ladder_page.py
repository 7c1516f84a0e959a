"""The contact ladder's page (`playroom ladder NAME=DIR[:GROUP] ... --out DIR`): the tests of
experiments/report/ladder.py written as one unit into DIR: ladder.md (the tables), ladder.csv
(every test of the family, unrounded, both kinds of p and their Holm adjustments),
ladder-trials.csv (every trial's values in every world it was tested in, with the machine and
commit that computed it: experiments/report/ladder_data.py), ladder.json (every trial's values,
every test, the family, the completeness check, the rungs) and ladder.png (the waterfall,
experiments/report/ladder_figure.py)."""

from __future__ import annotations

import math
import os
from itertools import pairwise
from pathlib import Path

import pandas as pd

from experiments.analysis import step_split
from experiments.analysis.results import BatchResults, check_out_dir
from experiments.analysis.trial_tests import ALPHA, survives
from experiments.report import ladder, ladder_data, rung_change
from experiments.report.figures import png_bytes
from experiments.report.ladder_figure import waterfall
from experiments.report.pages import machines_text, p_value, seeds_text, survive
from experiments.report.paired_text import cell_text, level_text
from experiments.trial_dir import provenance, storage

FILES = ("ladder.csv", ladder_data.FILE, "ladder.json", "ladder.png", "ladder.md")
HEAD = {k: k.removeprefix("competence_") for k in ladder.COMPETENCE}
WORLDS_TABLE_TITLE = (
    "Every rung's agents in each world (normalised competence, mean over the trials of the "
    "seeds every rung holds, trials in brackets):"
)


def _rows(table: pd.DataFrame, where: dict | None = None, **also: str) -> list[dict]:
    """The rows of `table` whose columns hold the values given, as dicts."""
    mask = pd.Series(True, index=table.index)
    for column, value in {**(where or {}), **also}.items():
        mask &= table[column] == value
    return [dict(r) for r in table[mask].to_dict("records")]


def rungs_table(
    rungs: list[ladder.Rung],
    beside: list[ladder.Rung],
    own: dict[str, BatchResults],
    against_first: bool = False,
) -> list[str]:
    """One row per rung: its batch, everything it changes from the rung before (a rung beside
    the ladder: from the last rung; `against_first`, a factorial's cells, which have no order:
    from the first) (rung_change.describe), its trials and where they were computed."""
    against = f"changes from {rungs[0].name}" if against_first else "changes from the rung before"
    head = f"| rung | batch | {against} | trials (seeds) | computed on |"
    lines = [head, "|---|---|---|---|---|"]
    before = None
    last = None
    for rung in [*rungs, *beside]:
        if rung in beside:
            before = last
        results = own[rung.name]
        group = results.groups[0]
        world = rung_change.RungWorld(
            results.configs[group], rung_change.recorded_backend(results.trials)
        )
        change = "(the first rung)" if before is None else rung_change.describe(before, world)
        seeds = sorted(int(s) for s in results.trials["seed"])
        lines.append(
            f"| {rung.name} | {rung.batch_dir.name} ({group}) | {change} | "
            f"{len(seeds)} ({seeds_text(seeds)}) | {machines_text(results)} |"
        )
        if before is None or not against_first:
            before = world
        if rung == rungs[-1]:
            last = world
    return lines


def steps_table(
    measures: list[ladder.Headline],
    steps: pd.DataFrame,
    levels: pd.DataFrame,
    order: list[str],
    beside: list[str],
) -> list[str]:
    """Rows: measures; columns: the first rung's mean, each step, the last rung's mean, the
    whole difference (of more than two rungs), the whole on every seed and each rung beside."""
    head = [f"{order[0]} (mean)", *(f"{a} -> {b}" for a, b in pairwise(order))]
    head.append(f"{order[-1]} (mean)")
    if len(order) > 2:  # of two rungs, the whole is the one step (ladder._comparisons)
        head.append("whole (first to last)")
    if (steps["kind"] == ladder.WHOLE_ALL).any():
        head.append("whole, every seed of the first and last rungs")
    head += [f"{order[-1]} -> {r} (beside)" for r in beside]
    lines = ["| measure | " + " | ".join(head) + " |", "|---" * (len(head) + 1) + "|"]
    for h in measures:
        kind = h.measure.kind
        level = {r["rung"]: r["mean"] for r in _rows(levels, tested=ladder.OWN, key=h.key)}
        cells = [level_text(kind, level.get(order[0], math.nan))]
        cells += [cell_text(kind, r) for r in _rows(steps, key=h.key, kind=ladder.STEP)]
        cells.append(level_text(kind, level.get(order[-1], math.nan)))
        cells += [cell_text(kind, r) for r in _rows(steps, key=h.key, kind=ladder.WHOLE)]
        for which in (ladder.WHOLE_ALL, ladder.BESIDE):
            cells += [cell_text(kind, r) for r in _rows(steps, key=h.key, kind=which)]
        lines.append(f"| {h.label} | " + " | ".join(cells) + " |")
    return lines


def split_table(splits: pd.DataFrame, levels: pd.DataFrame) -> list[str]:
    """Each step's competence split in each test world; then every rung in every world."""
    if splits.empty:
        return ["No rung was tested in another world (`playroom eval DIR --world W`)."]
    keys = list(ladder.COMPETENCE)
    lines = [
        "Each step from A to B (A the earlier rung) in two parts that add up to it, seed by "
        "seed: both rungs' agents tested in one world, and the rungs' own worlds against it. "
        "For two rungs neither of whose own worlds is the test world, the second part contrasts "
        "three worlds and is not what either rung's own world does alone "
        "(experiments/analysis/step_split.py).",
        "",
    ]
    lines += ["| step | part | " + " | ".join(HEAD[k] for k in keys) + " |"]
    lines.append("|---" * (len(keys) + 2) + "|")
    seen = splits[["from", "to", "kind", "world", "part"]].drop_duplicates()
    for case in seen.to_dict("records"):
        by_key = {r["key"]: r for r in _rows(splits, case)}
        cells = [cell_text("share", by_key[k]) if k in by_key else "" for k in keys]
        step = f"{case['from']} -> {case['to']}" + (
            " (whole)" if case["kind"] == ladder.WHOLE else ""
        )
        part = step_split.PART_TEXT[case["part"]].format(world=case["world"])
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


def family_lines(steps: pd.DataFrame, splits: pd.DataFrame) -> list[str]:
    """The family, as declared (ladder.FAMILY), with its counts."""
    n = step_split.counts([steps, splits])
    lines = [f"One family of {n['family']} tests, fixed by the rungs and the measures before any "]
    lines[0] += "value was read (`experiments/report/ladder.py` FAMILY):"
    lines += ["", *(f"- {part}" for part in ladder.FAMILY), ""]
    lines.append(
        f"{n['made']} of them could be made (a comparison whose every pair is equal, or whose "
        f"rungs were not tested in a world, has no p and does not count in Holm's m). Holm's "
        f"correction at {ALPHA} over them: {survive(n['t'])} with the paired t, {n['rank']} with "
        "the Wilcoxon signed-rank test."
    )
    return lines


def disagreement_lines(measures: list[ladder.Headline], tests: pd.DataFrame) -> list[str]:
    """Every cell whose Holm star differs between the paired t and the signed-rank test."""
    label = {h.key: h.label for h in measures} | {k: HEAD[k] for k in ladder.COMPETENCE}
    differ = [r for r in tests.to_dict("records") if step_split.stars_differ(r)]
    if not differ:
        return ["None: every star of the page is the same under both tests."]
    lines = []
    for r in differ:
        part = step_split.PART_SHORT.get(r["part"], "")
        where = "" if r["part"] == ladder.STEP else ", " + part.format(world=r["world"])
        starred = "the t" if survives(float(r["p_holm"])) else "the signed-rank test"
        lines.append(
            f"- {label.get(r['key'], r['key'])}, {r['from']} -> {r['to']} ({r['kind']}{where}): "
            f"starred by {starred} only ({p_value(float(r['p']))}; rank "
            f"{p_value(float(r['p_rank']))})"
        )
    return lines


def _seeds_or_none(seeds: list[int]) -> str:
    return seeds_text(seeds) if seeds else "none"


# What the seeds some rungs hold beyond the common ones enter, on a ladder's page.
LADDER_OTHER_SEEDS = (
    "Every step is taken on the seeds every rung holds; the others enter only comparisons of "
    "rungs that both hold them (the whole on every seed of the first and last rungs)."
)


def completeness_lines(check: pd.DataFrame, other_seeds: str = LADDER_OTHER_SEEDS) -> list[str]:
    """The completeness check (ladder.completeness) and its verdict (`completeness_verdict`)."""
    worlds = [ladder.OWN, *ladder.WORLDS]
    head = ["rung", "seeds", *(f"seeds lacking ({w})" for w in worlds), "values not finite"]
    lines = ["| " + " | ".join(head) + " |", "|---" * len(head) + "|"]
    for r in check.to_dict("records"):
        missing = [_seeds_or_none(r[f"missing_{w}"]) for w in worlds]
        lines.append(
            f"| {r['rung']} | {r['seeds']} | " + " | ".join(missing) + f" | {r['not_finite']} |"
        )
    return [
        "What it checks: that every rung (and every rung beside the ladder) holds every seed "
        "any rung holds, in its own world and in each test world; a value that is not finite "
        "(a trial with no value for a measure, such as catches per grasp without a grasp) is "
        "counted, and its pairs are left out of that measure's tests.",
        "",
        *lines,
        "",
        completeness_verdict(check, other_seeds),
    ]


def completeness_verdict(check: pd.DataFrame, other_seeds: str = LADDER_OTHER_SEEDS) -> str:
    """The verdict: complete; or, where the rungs merely hold different seeds (each trial tested
    in every world, as designed when the ends hold more seeds), which rungs lack which seeds
    and `other_seeds`, what the page does with the seeds not every rung holds; or incomplete,
    naming each rung whose trials lack a test world (a cross-evaluation missing)."""
    if check["complete"].all():
        return "Complete: every rung holds every seed in its own world and in both test worlds."
    untested = []
    for r in check.to_dict("records"):
        worlds = [w for w in ladder.WORLDS if r[f"missing_{w}"] != r["missing_own"]]
        if worlds:
            untested.append(f"{r['rung']} ({', '.join(worlds)})")
    if untested:
        return (
            "Incomplete: some trials were not tested in every world: "
            + "; ".join(untested)
            + ". The steps are taken on the seeds every rung holds in each world."
        )
    # Rungs lacking the same seeds named together: "a, b lack 32–63; c lacks 16–63".
    by_lacking: dict[tuple[int, ...], list[str]] = {}
    for r in check.to_dict("records"):
        if r["missing_own"]:
            by_lacking.setdefault(tuple(r["missing_own"]), []).append(r["rung"])
    lacks = "; ".join(
        f"{', '.join(names)} {'lacks' if len(names) == 1 else 'lack'} {seeds_text(list(seeds))}"
        for seeds, names in by_lacking.items()
    )
    return (
        "Every trial was tested in both test worlds. The rungs hold different seeds: "
        f"{lacks}. {other_seeds}"
    )


def markdown(
    command: str, rungs, beside, read: ladder.LadderRead, steps, splits, levels, check
) -> str:
    order, others = [r.name for r in rungs], [r.name for r in beside]
    tests = pd.concat([steps.assign(part=ladder.STEP, world=ladder.OWN), splits], ignore_index=True)
    here = provenance.describe(provenance.short_record(provenance.machine_record()))
    lines = [
        "# The contact ladder",
        "",
        f"Written by `{command}`; statistics computed on {here}.",
        "",
        f"Every trial's values, in every world it was tested in, with the machine and commit "
        f"that computed it: [{ladder_data.FILE}]({ladder_data.FILE}), from which every number "
        "here can be computed again.",
        "",
        "Tests over trials, the agent the unit, paired by seed: each cell is the mean over seeds "
        "of the later rung minus the earlier [95% t interval], the paired t's two-sided p, the "
        "Wilcoxon signed-rank test's two-sided p (rank p), (pairs); * after a p where it "
        "survives Holm's correction over the page's one family (below), for its kind of p. No "
        "test here pools tests or words across agents. Shares in percentage points.",
        "",
        *rungs_table(rungs, beside, read.own),
        "",
        "## Each rung's step, given the rules before it",
        "",
        "A step measures what the rule its rung changes does given the rules before it, in "
        "this one order: another order, or a rule that acts with another, can give the same "
        "rule another share of the whole.",
        "",
        *steps_table(read.measures, steps, levels, order, others),
        "",
        "![waterfall](ladder.png)",
        "",
        "## Both tested in one world, or their own worlds against it? (cross-evaluation)",
        "",
        *split_table(splits, levels),
    ]
    if read.missing:
        lines += ["", "Not tested in another world:", "", *(f"- {m}" for m in read.missing)]
    lines += ["", "## The family of tests", "", *family_lines(steps, splits)]
    lines += ["", "## Where the t and the signed-rank test disagree on a star", ""]
    lines += disagreement_lines(read.measures, tests)
    lines += ["", "## Completeness", "", *completeness_lines(check)]
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
    read = ladder.read_ladder(rungs, beside)
    return storage.write_files(out, ladder_files(read, rungs, beside, command))[-1]


def ladder_files(
    read: ladder.LadderRead, rungs: list[ladder.Rung], beside: list[ladder.Rung], command: str
) -> dict[str, bytes]:
    """Every file of the page (FILES, the page last) from what `ladder.read_ladder` read."""
    values, measures = read.values, read.measures
    order, others = [r.name for r in rungs], [r.name for r in beside]
    steps = ladder.step_tests(values, order, others, measures)
    splits = ladder.split_tests(values, order, others)
    steps, splits = step_split.with_holm(steps, splits)
    # The rungs' means on the seeds the steps pair, so that the first plus the steps is the last.
    common = ladder.common_seeds(values, order)
    levels = ladder.levels(values[values["seed"].isin(common) | values["rung"].isin(others)])
    check = ladder.completeness(values, [*order, *others])
    page = markdown(command, rungs, beside, read, steps, splits, levels, check)
    rung_record = [
        {"name": r.name, "batch": str(r.batch_dir), "group": r.group, "beside": r in beside}
        for r in [*rungs, *beside]
    ]
    record = {
        "command": command,
        "rungs": rung_record,
        "measures": {h.key: {"label": h.label, "kind": h.measure.kind} for h in measures},
        "family": list(ladder.FAMILY),
        "values": json_records(values),
        "steps": json_records(steps),
        "splits": json_records(splits),
        "completeness": json_records(check),
        "levels": json_records(levels),
        "not_tested": read.missing,
    }
    tests = pd.concat([steps.assign(part=ladder.STEP, world=ladder.OWN), splits], ignore_index=True)
    keys = [h.key for h in measures]
    trials = ladder_data.trial_table(values, read.provenance, keys)
    return {
        "ladder.csv": tests.to_csv(index=False).encode(),
        ladder_data.FILE: trials.to_csv(index=False).encode(),
        "ladder.json": storage.json_bytes(record),
        "ladder.png": png_bytes(waterfall(measures, steps, levels, order)),
        "ladder.md": page.encode(),
    }
