"""HTML of the report and the comparison: numbers turned into text, tables, and the pages
rendered from the Jinja2 templates in `experiments/report/templates/`, then written to disk.

Autoescape is on for every template: group labels, trial names, paths and configs come from
the user's files and reach the page as text, never as markup. Figures are embedded as
base64 PNG data URIs so that a page is one self-contained file.
"""

from __future__ import annotations

import base64
import json
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd
from jinja2 import Environment, PackageLoader, StrictUndefined, select_autoescape

from experiments.analysis.results import BatchResults
from experiments.analysis.stats import STRATEGIES
from experiments.analysis.trial_rows import COMPETENCE_SCOPES
from experiments.report.figures import FigureFile
from experiments.trial_dir import storage


@dataclass(frozen=True)
class Table:
    """A table of plain-text cells: header (n columns) and rows (lists of n strings)."""

    header: list[str]
    rows: list[list[str]]


# Numbers as text ------------------------------------------------------------------------------


# How pages name the vocal tracts (models/tracts.py names them for settings).
TRACT_NAMES = {"vtl": "VocalTractLab", "diva": "DIVA (the study's)"}


# Below this a p-value has underflowed in its computation (a t or χ² far in the tail): printed
# as this bound (the smallest normal double is 2.2e-308; a round bound above it).
P_FLOOR = 1e-300


def pct(x: float, digits: int = 0) -> str:
    """A fraction as a percentage ("46%"); "n/a" for NaN or inf."""
    return "n/a" if not np.isfinite(x) else f"{100 * x:.{digits}f}%"


def num(x: float, digits: int = 2) -> str:
    """A number with `digits` decimals; "n/a" for NaN or inf."""
    return "n/a" if not np.isfinite(x) else f"{x:.{digits}f}"


def p_value(p: float) -> str:
    """A p value as text, with 2 significant digits ("p = 0.063", "p = 1.4e-17"); a p that
    underflowed (0, or below the float range's normal numbers, where its digits are lost) as
    a bound, "p < 1e-300", never as 0."""
    if not np.isfinite(p):
        return "n/a"
    if p < P_FLOOR:
        return f"p < {P_FLOOR:.0e}"
    return f"p = {p:.2g}" if p >= 1e-3 else f"p = {p:.1e}"


# Below this many trials a group's t interval rests on too few values to trust: the pages say
# so beside the interval and above the first table.
FEW_TRIALS = 5


def survive(n: int) -> str:
    """ "N survive", or "1 survives": how many tests survive a correction, as the pages say it."""
    return f"{n} survives" if n == 1 else f"{n} survive"


def interval_notes(low: float, high: float, n: int) -> list[str]:
    """Warnings for an interval that would mislead as printed: zero width (all trials equal,
    or narrower than the 0.1% printed) and fewer than FEW_TRIALS trials behind it."""
    notes = []
    if pct(low, 1) == pct(high, 1):
        notes.append("all trials equal" if low == high else "interval under 0.1% wide")
    if n < FEW_TRIALS:
        notes.append(f"fewer than {FEW_TRIALS} trials")
    return notes


def ci_text(row: pd.Series) -> str:
    """A row of `stats.competence_summary` as "mean [95% CI low, high] (n=...)", with
    `interval_notes` after n where the interval would mislead."""
    if not np.isfinite(row["mean"]):
        return "n/a"
    if not np.isfinite(row["low"]):
        return f"{pct(row['mean'], 1)} (n={row['n']}, no interval)"
    interval = f"[95% CI {pct(row['low'], 1)}, {pct(row['high'], 1)}]"
    notes = "".join(f"; {note}" for note in interval_notes(row["low"], row["high"], row["n"]))
    return f"{pct(row['mean'], 1)} {interval} (n={row['n']}{notes})"


def shares_text(row: pd.Series) -> str:
    """A row of `stats.strategy_table` as "hand / tool / vocal (n=... tests)"."""
    if row["n"] == 0:
        return "no tests here"
    shares = " / ".join(pct(row[s]) for s in STRATEGIES)
    return f"{shares} (n={row['n']} tests)"


def machines_text(results: BatchResults) -> str:
    """Where a batch's trials were computed, each CPU and commit once ("AMD EPYC, commit
    abc1234; ...")."""
    where = results.provenance
    if "status" not in where or where.empty:
        return "not recorded"
    computed = where[where["role"] == "computed"]
    found = computed.drop_duplicates(["cpu", "commit"])
    return "; ".join(f"{r.cpu}, commit {r.commit}" for r in found.itertuples())


def seeds_text(seeds: list[int]) -> str:
    """Seeds as a range ("0–9") when they are consecutive, else listed."""
    seeds = sorted(seeds)
    if seeds == list(range(seeds[0], seeds[-1] + 1)) and len(seeds) > 2:
        return f"{seeds[0]}–{seeds[-1]}"
    return ", ".join(map(str, seeds))


# Tables shared by the report and the comparison -----------------------------------------------


def settings_table(results: BatchResults) -> Table:
    """One row per group: trials, seeds, iterations, babbling, preset, stick return, the
    hand's reach as the group's backend declared it (backend.json), vocal tract, placements,
    package version."""
    rows = []
    for group in results.groups:
        trials = results.trials[results.trials["group"] == group]
        config = results.configs[group]
        rows.append(
            [
                group,
                str(len(trials)),
                seeds_text(trials["seed"].tolist()),
                str(config["trial"]["iterations"]),
                str(config["trial"]["babbling"]),
                str(config["trial"].get("preset", "?")),
                str(config["world"].get("stick_return", "?")),
                f"{trials['reach'].iloc[0]:g} m" if "reach" in trials else "?",
                TRACT_NAMES.get(config["world"]["voice"], config["world"]["voice"]),
                str(trials["n_placements"].iloc[0]),
                str(config.get("package_version", "?")),
            ]
        )
    header = [
        "group",
        "trials",
        "seeds",
        "iterations",
        "babbling",
        "preset",
        "stick return",
        "hand's reach",
        "vocal tract",
        "placements per ring",
        "package version",
    ]
    return Table(header, rows)


def trials_table(results: BatchResults) -> Table:
    """One row per trial: its competence, vocal numbers, diverged iterations and cost."""
    rows = [
        [
            r["trial"],
            r["group"],
            str(r["seed"]),
            *[pct(r[f"competence_{k}"], 1) for k in COMPETENCE_SCOPES],
            pct(r["share_below_threshold"]),
            num(r["median_names"]),
            num(r["median_distractors"]),
            str(r["diverged"]),
            num(r["seconds"] / r["timed_iterations"], 4),
        ]
        for _, r in results.trials.iterrows()
    ]
    header = [
        "trial",
        "group",
        "seed",
        "competence",
        "ring 1",
        "ring 2",
        "ring 3",
        "words < threshold",
        "median names",
        "median distractors",
        "diverged",
        "s / iteration",
    ]
    return Table(header, rows)


# Rows of BatchResults.provenance: who computed a trial, who evaluated it.
ROLES = ("computed", "evaluated")


def _counts_text(rows: pd.DataFrame, groups: list[str]) -> str:
    """How many distinct trials `rows` hold, per group when the page shows several."""
    n = rows["trial"].nunique()
    if n == 0 or len(groups) < 2:
        return str(n)
    per = [f"{g} {rows.loc[rows['group'] == g, 'trial'].nunique()}" for g in groups]
    return f"{n} ({', '.join(p for p in per if not p.endswith(' 0'))})"


def where_table(results: BatchResults, computed_on: dict[str, str] | None) -> tuple[Table, str]:
    """Where the trials ran: one row per machine and library set (CPU, NumPy's SIMD, BLAS
    kernel, numpy and mujoco versions, host, commit) with the trials computed and evaluated
    there; trials from before provenance was recorded count as "not recorded". Returns the
    table and a sentence about trials computed on more than one machine, and about
    `computed_on`, the machine computing the page (provenance's short record)."""
    from experiments.trial_dir.provenance import SHORT_FIELDS, describe

    where = results.provenance
    if "status" not in where:  # results built without it (none read from a batch)
        return Table([], []), "Not recorded."
    header = ["CPU", "NumPy SIMD", "BLAS (kernel)", "numpy", "mujoco", "host", "commit"]
    header += [f"trials {role}" for role in ROLES]
    unknown = {"not recorded": "not recorded (older trials)", "unreadable": "record unreadable"}
    rows = []
    # Recorded machines first, in the order trials were read; unknown ones last.
    groups = where.groupby(["status", *SHORT_FIELDS], sort=False)
    for values, here in sorted(groups, key=lambda g: g[0][0] != "recorded"):
        status, *fields = map(str, values)  # text: the records' short fields
        if status != "recorded":
            fields = [unknown.get(status, status)] + [""] * (len(SHORT_FIELDS) - 1)
        counts = [_counts_text(here[here["role"] == role], results.groups) for role in ROLES]
        rows.append([*fields, *counts])
    computed = where[where["role"] == "computed"]
    moved = int((computed.groupby("trial").size() > 1).sum())
    note = (
        f"{moved} trial{'s' if moved != 1 else ''} changed machine or library set on a resume "
        f"and count{'' if moved != 1 else 's'} under each."
        if moved
        else "Each trial was computed on one machine and library set."
    )
    # The page's own statistics are computed on `computed_on`: a bootstrap interval's last digits
    # follow its BLAS kernel (OpenBLAS's SkylakeX and Haswell kernels, measured).
    note += (
        f" This page's statistics were computed on {describe(computed_on)}; the last digits "
        "of their bootstrap intervals follow that machine's BLAS kernel."
    )
    return Table(header, rows), note


# Pages -----------------------------------------------------------------------------------------


def _data_uri(png: bytes) -> str:
    return "data:image/png;base64," + base64.b64encode(png).decode("ascii")


def _pretty_json(obj: Any) -> str:
    return json.dumps(obj, indent=2, sort_keys=True)


def _environment() -> Environment:
    env = Environment(
        loader=PackageLoader("experiments.report", "templates"),
        # Every template here is HTML; default=True also escapes any template named otherwise.
        autoescape=select_autoescape(enabled_extensions=("html.j2",), default=True),
        # A misspelt variable fails the report instead of leaving a blank in it.
        undefined=StrictUndefined,
        trim_blocks=True,
        lstrip_blocks=True,
        keep_trailing_newline=True,
    )
    env.filters["data_uri"] = _data_uri
    env.filters["pretty_json"] = _pretty_json
    return env


_ENV = _environment()


def render(template: str, **context: Any) -> str:
    """The page of `template` (a file name in experiments/report/templates/) filled with
    `context`."""
    return _ENV.get_template(template).render(**context)


def write_page(
    out_dir: Path,
    figures: list[FigureFile],
    page_name: str,
    page: str,
    beside: dict[str, bytes] | None = None,
) -> Path:
    """The PNGs, the files `beside` it (its summary) and the page as one unit
    (`storage.write_files`), the page last: a write that fails (disk full) leaves nothing,
    and a page on disk means its figures and summary are there too. Returns the page's path."""
    files = {figure.name: figure.png for figure in figures}
    files.update(beside or {})
    files[page_name] = page.encode("utf-8")
    return storage.write_files(out_dir, files)[-1]
