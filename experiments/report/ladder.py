"""The contact ladder read as one set of tests: worlds from the study's kinematic rules to the
physical backend, one rule changed per rung (experiments/batches/contact-ladder/), each rung a
batch directory, or one group of it where the batch holds both backends (the comparison's
kinematic and physical halves are the ladder's first and last rungs).

For every headline measure (`HEADLINE`, entries of the registry experiments/report/measures.py)
one value per trial, the agent the unit. Each step, from a rung to the next, is the mean over
seeds of the later rung's value minus the earlier's, paired by seed, with its 95% interval and
the paired t test's two-sided p; the whole difference is the last rung minus the first on the
seeds both hold, and the steps' sum is set against it (the same seeds in every rung and no
missing value make them equal; otherwise the page says by how much they differ). A rung beside
the ladder (settling, after the physical backend) is set against the last rung.

Cross-evaluation, where the rungs' agents were also tested in the kinematic and physical
worlds (`playroom eval DIR --world W`): each step of each competence measure splits, for a
test world W, into what the agents learned (the later rung's agents against the earlier's,
both tested in W) and what the rungs' own test worlds do ((B own - B in W) - (A own - A in W),
per seed): the two add up to the step exactly, seed by seed.

Holm's correction runs over every test of the page. The page itself: experiments/report/
ladder_page.py; the waterfall figure: experiments/report/ladder_figure.py.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from itertools import pairwise
from pathlib import Path

import numpy as np
import pandas as pd

from experiments.analysis import eval_world_results
from experiments.analysis.geometry import Geometry
from experiments.analysis.results import BatchResults, ReportError, collect
from experiments.analysis.stats import paired_difference, regions
from experiments.analysis.strategies import DEFINITIONS
from experiments.analysis.trial_tests import holm, paired_arrays
from experiments.analysis.trial_values import VALUE
from experiments.report.measures import Measure, registry

OWN = "own"
WORLDS = ("kinematic", "physical")
STEP, WHOLE, WHOLE_ALL, BESIDE = "step", "whole", "whole_all", "beside"
COMPETENCE = ("competence_all", "competence_ring1", "competence_ring2", "competence_ring3")


@dataclass(frozen=True)
class Rung:
    """One rung: a name for the page, a batch directory, the group of it (None: its only one)."""

    name: str
    batch_dir: Path
    group: str | None = None


@dataclass(frozen=True)
class Headline:
    """One measure of the ladder: a registry entry's part, under a short label."""

    key: str
    measure: Measure
    part: str
    label: str


def parse_rung(text: str) -> Rung:
    """NAME=DIR or NAME=DIR:GROUP -> Rung; ValueError naming what is missing."""
    name, sep, where = text.partition("=")
    if not sep or not name or not where:
        raise ValueError(f"a rung is NAME=DIR or NAME=DIR:GROUP, not {text!r}")
    folder, _, group = where.partition(":")
    return Rung(name, Path(folder), group or None)


def headline(geometry: Geometry) -> list[Headline]:
    """The ladder's measures: competence per ring, the tool share of the study's tests in each
    region under both definitions of a tool use, stick grasps, catches and catches per grasp,
    the study's tool uses that barely moved the stick (what its rule counts of a stick nudged
    but not pushed away), words within the recognition distance and the names' gap."""
    by_name = {m.name: m for m in registry(geometry)}
    picked = [(name, VALUE, by_name[name].label) for name in COMPETENCE]
    for definition in DEFINITIONS:
        for region in regions(geometry.hand_limit, geometry.stick_limit):
            name = f"strategies_study_{definition}_{region.replace(' ', '_')}"
            picked.append((name, "tool", f"tool share, study's tests, {region} ({definition})"))
    picked += [
        ("stick_grasps_per_1000_arm", VALUE, by_name["stick_grasps_per_1000_arm"].label),
        ("toy_catches_per_1000_arm", VALUE, by_name["toy_catches_per_1000_arm"].label),
        ("toy_catches_per_stick_grasp", VALUE, "Toys caught with the stick per stick grasp"),
        (
            "study_tool_uses_below_min_motion",
            VALUE,
            by_name["study_tool_uses_below_min_motion"].label,
        ),
        ("words_within", VALUE, by_name["words_within"].label),
        ("names_vs_distractors", VALUE, by_name["names_vs_distractors"].short),
    ]
    return [
        Headline(name if part == VALUE else f"{name}:{part}", by_name[name], part, label)
        for name, part, label in picked
    ]


def _selected(results: BatchResults, rung: Rung) -> BatchResults:
    if rung.group is None:
        if len(results.groups) != 1:
            raise ReportError(
                f"{rung.batch_dir} holds groups {', '.join(results.groups)}: name one "
                f"({rung.name}={rung.batch_dir}:GROUP)"
            )
        return results
    if rung.group not in results.groups:
        raise ReportError(
            f"{rung.batch_dir} holds no group {rung.group!r} (it holds {', '.join(results.groups)})"
        )
    return results.select(rung.group)


def rung_results(rung: Rung, tested: str = OWN) -> BatchResults:
    """A rung's trials as tested in their own world (OWN) or in eval world `tested`."""
    if tested == OWN:
        return _selected(collect(rung.batch_dir), rung)
    return _selected(eval_world_results.collect(rung.batch_dir, tested), rung)


def values_of(results: BatchResults, rung: str, tested: str, measures: list[Headline]) -> list:
    """Rows (rung, tested, seed, key, value): each headline measure's value per trial."""
    rows = []
    for h in measures:
        frame = h.measure.values(results)
        for seed, value in zip(frame["seed"], frame[h.part], strict=True):
            rows.append((rung, tested, int(seed), h.key, float(value)))
    return rows


VALUE_COLUMNS = ["rung", "tested", "seed", "key", "value"]


def _series(values: pd.DataFrame, rung: str, key: str, tested: str = OWN) -> pd.Series:
    mine = values[(values["rung"] == rung) & (values["key"] == key) & (values["tested"] == tested)]
    return mine.set_index("seed")["value"]


def _paired(b: pd.Series, a: pd.Series) -> dict[str, float]:
    """B minus A over the seeds both hold (finite on both sides)."""
    x, y = paired_arrays(b, a)
    mean, low, high, p = paired_difference(x, y)
    return {"mean": mean, "low": low, "high": high, "p": p, "n": len(x)}


def common_seeds(values: pd.DataFrame, order: list[str]) -> set[int]:
    """The seeds every rung of the ladder holds."""
    return set.intersection(*(set(values.loc[values["rung"] == r, "seed"]) for r in order))


def _steps(order: list[str], beside: list[str]) -> list[tuple[str, str, str]]:
    """(kind, from, to) of every comparison the page makes: each step, the whole (first rung to
    last) and each rung beside the ladder against the last rung."""
    steps = [(STEP, a, b) for a, b in pairwise(order)]
    return [*steps, (WHOLE, order[0], order[-1]), *((BESIDE, order[-1], r) for r in beside)]


def step_tests(
    values: pd.DataFrame, order: list[str], beside: list[str], measures: list[Headline]
) -> pd.DataFrame:
    """One row per (measure, step): each step of the ladder and the whole difference (first
    rung to last), on the seeds every rung holds, so that the steps' sum is the whole wherever
    no value is missing; the whole on every seed the first and last rungs hold (WHOLE_ALL),
    where they hold more; and each rung beside the ladder against the last rung."""
    common = common_seeds(values, order)
    ladder = values[values["seed"].isin(common)]
    pairs = [(kind, a, b, ladder) for kind, a, b in _steps(order, [])]
    ends = [set(values.loc[values["rung"] == r, "seed"]) for r in (order[0], order[-1])]
    if len(ends[0] & ends[1]) > len(common):
        pairs.append((WHOLE_ALL, order[0], order[-1], values))
    pairs += [(BESIDE, order[-1], r, values) for r in beside]
    rows = []
    for h in measures:
        for kind, a, b, table in pairs:
            tested = _paired(_series(table, b, h.key), _series(table, a, h.key))
            rows.append({"key": h.key, "kind": kind, "from": a, "to": b, **tested})
    return pd.DataFrame(rows)


def split_tests(values: pd.DataFrame, order: list[str], beside: list[str]) -> pd.DataFrame:
    """Each step (and the whole difference, and each rung beside) of each competence measure
    split, in each test world both rungs' agents were tested in, into `learned` and `worlds`
    (module docstring); steps whose rungs lack a test world are left out."""
    values = values[values["seed"].isin(common_seeds(values, order)) | values["rung"].isin(beside)]
    rows = []
    for key in COMPETENCE:
        for kind, a, b in _steps(order, beside):
            for world in WORLDS:
                a_in, b_in = _series(values, a, key, world), _series(values, b, key, world)
                if a_in.empty or b_in.empty:
                    continue
                a_own, b_own = _series(values, a, key), _series(values, b, key)
                worlds = (b_own - b_in) - (a_own - a_in)  # per seed, NaN where one lacks it
                zero = pd.Series(0.0, index=worlds.index)
                for part, tested in (
                    ("learned", _paired(b_in, a_in)),
                    ("worlds", _paired(worlds.dropna(), zero)),
                ):
                    rows.append(
                        {"key": key, "kind": kind, "from": a, "to": b, "world": world}
                        | {"part": part, **tested}
                    )
    return pd.DataFrame(rows)


def with_holm(*tables: pd.DataFrame) -> tuple[pd.DataFrame, ...]:
    """The tables with `p_holm`: Holm's adjustment over every p of all of them."""
    ps = [float(p) for t in tables if len(t) for p in t["p"]]
    adjusted = holm(ps)
    out, start = [], 0
    for table in tables:
        table = table.copy()
        table["p_holm"] = adjusted[start : start + len(table)] if len(table) else []
        start += len(table)
        out.append(table)
    return tuple(out)


def steps_sum(steps: pd.DataFrame) -> pd.DataFrame:
    """Per measure: the whole difference, its interval, the steps' sum and the whole minus
    that sum (0 where every rung holds the same seeds with every value)."""
    rows = []
    for key, mine in steps.groupby("key", sort=False):
        whole = mine[mine["kind"] == WHOLE].iloc[0]
        total = float(mine.loc[mine["kind"] == STEP, "mean"].sum(min_count=1))
        within = bool(whole["low"] <= total <= whole["high"]) if math.isfinite(total) else False
        rows.append(
            {"key": key, "whole": whole["mean"], "low": whole["low"], "high": whole["high"]}
            | {"steps_sum": total, "whole_minus_sum": whole["mean"] - total, "within": within}
        )
    return pd.DataFrame(rows)


def levels(values: pd.DataFrame) -> pd.DataFrame:
    """Each rung's mean over its trials per measure and test world, with the trials counted."""
    finite = values[np.isfinite(values["value"])]
    grouped = finite.groupby(["rung", "tested", "key"], sort=False)["value"]
    return grouped.agg(mean="mean", n="count").reset_index()


def read_ladder(
    rungs: list[Rung], beside: list[Rung] | None = None
) -> tuple[pd.DataFrame, list[Headline], dict[str, BatchResults], list[str]]:
    """(values, headline measures, each rung's own results, notes of cross-evaluations not
    found) of the rungs in ladder order and those beside it. ReportError (one line) for a rung
    that cannot be read, fewer than two rungs, or two rungs of one name."""
    every = [*rungs, *(beside or [])]
    if len(rungs) < 2:
        raise ReportError("a ladder needs at least two rungs (NAME=DIR[:GROUP] each)")
    names = [r.name for r in every]
    if len(set(names)) != len(names):
        raise ReportError(f"two rungs share a name: {', '.join(names)}")
    own = {r.name: rung_results(r) for r in every}
    measures = headline(Geometry.of(own[rungs[0].name]))
    rows, missing = [], []
    for rung in every:
        rows += values_of(own[rung.name], rung.name, OWN, measures)
        competence = [h for h in measures if h.key in COMPETENCE]
        for world in WORLDS:
            try:
                tested = rung_results(rung, world)
            except ReportError as exc:
                missing.append(f"{rung.name} in the {world} world: {exc}")
                continue
            rows += values_of(tested, rung.name, world, competence)
    return pd.DataFrame(rows, columns=VALUE_COLUMNS), measures, own, missing
