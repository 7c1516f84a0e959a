"""The contact ladder read as one set of tests: worlds from the study's kinematic rules to the
physical backend, one rule changed per rung (experiments/batches/contact-ladder/), each rung a
batch directory, or one group of it where the batch holds both backends (the comparison's
kinematic and physical halves are the ladder's first and last rungs).

For every headline measure (`HEADLINE`, entries of the registry experiments/report/measures.py)
one value per trial, the agent the unit. Each step, from a rung to the next, is what the rule
the later rung changes does given the rules before it, in this one order: the mean over seeds
of the later rung's value minus the earlier's, paired by seed, with its 95% interval, the
paired t test's two-sided p and the Wilcoxon signed-rank p (experiments/analysis/
step_split.py). The whole difference is the last rung minus the first; a rung beside the
ladder (settling, after the physical backend) is set against the last rung. Steps are taken on
the seeds every rung holds; `completeness` says whether every rung holds every seed in its own
world and in every test world, and what it lacks.

Cross-evaluation, where the rungs' agents were also tested in the kinematic and physical
worlds (`playroom eval DIR --world W`): each step of each competence measure splits, for a
test world W, into both rungs' agents tested in W and the rungs' own worlds against W
(step_split.py, which says what each computes).

The family of tests is declared here (`FAMILY`, `family`) from the rungs and the measures
alone, before any value is read; Holm's correction runs over it, for each kind of p. The page
itself: experiments/report/ladder_page.py; the per-trial data written beside it:
experiments/report/ladder_data.py; the waterfall figure: experiments/report/ladder_figure.py.
"""

from __future__ import annotations

from dataclasses import dataclass
from itertools import pairwise
from pathlib import Path

import numpy as np
import pandas as pd

from experiments.analysis import eval_world_results, step_split
from experiments.analysis.geometry import Geometry
from experiments.analysis.results import BatchResults, ReportError, collect
from experiments.analysis.stats import regions
from experiments.analysis.strategies import DEFINITIONS
from experiments.analysis.trial_values import VALUE
from experiments.report.measures import Measure, registry

OWN = "own"
WORLDS = ("kinematic", "physical")
STEP, WHOLE, WHOLE_ALL, BESIDE = "step", "whole", "whole_all", "beside"
COMPETENCE = ("competence_all", "competence_ring1", "competence_ring2", "competence_ring3")
# The page's one family of tests, fixed by the rungs and the measures before any value is read
# (`family` lists it; the page prints this): Holm's correction runs over all of it.
FAMILY = (
    "every headline measure: each step, the whole (first rung to last) where there are more "
    "than two rungs (of two, the whole is the one step, tested once), and each rung beside the "
    "ladder against the last rung, on the seeds every rung holds, and the whole on every seed "
    "of the first and last rungs where they hold more seeds than every rung does",
    "every competence measure: each of those comparisons in each test world (kinematic, "
    "physical), split in its two parts (both rungs' agents tested there; the rungs' own "
    "worlds against it); a part whose rungs were not tested in that world is a test that "
    "could not be made (no p, not counted in Holm's m)",
)


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


def common_seeds(values: pd.DataFrame, order: list[str]) -> set[int]:
    """The seeds every rung of the ladder holds."""
    return set.intersection(*(set(values.loc[values["rung"] == r, "seed"]) for r in order))


def _comparisons(order: list[str], beside: list[str]) -> list[tuple[str, str, str]]:
    """(kind, from, to) of every comparison the page makes: each step, the whole (first rung to
    last) where there are more than two rungs, and each rung beside the ladder against the last
    rung. Of two rungs the whole is the one step: tested once, not twice in Holm's m."""
    steps = [(STEP, a, b) for a, b in pairwise(order)]
    whole = [(WHOLE, order[0], order[-1])] if len(steps) > 1 else []
    return [*steps, *whole, *((BESIDE, order[-1], r) for r in beside)]


FAMILY_COLUMNS = ["key", "kind", "from", "to", "world", "part"]


def family(
    order: list[str], beside: list[str], measures: list[Headline], ends_hold_more: bool
) -> pd.DataFrame:
    """Every test of the page (FAMILY), from the rungs and the measures alone: columns key,
    kind, from, to, world (OWN for a step of the rungs' own worlds) and part ("step" or a
    step_split part). `ends_hold_more`: the first and last rungs hold seeds some rung lacks."""
    rows = []
    comparisons = _comparisons(order, beside)
    ladder = [c for c in comparisons if c[0] != BESIDE]
    whole_all = [(WHOLE_ALL, order[0], order[-1])] if ends_hold_more else []
    for h in measures:
        for kind, a, b in [*ladder, *whole_all, *comparisons[len(ladder) :]]:
            rows.append({"key": h.key, "kind": kind, "from": a, "to": b, "world": OWN})
            rows[-1]["part"] = STEP
    for key in COMPETENCE:
        for kind, a, b in comparisons:
            for world in WORLDS:
                for part in step_split.PARTS:
                    rows.append({"key": key, "kind": kind, "from": a, "to": b, "world": world})
                    rows[-1]["part"] = part
    return pd.DataFrame(rows, columns=FAMILY_COLUMNS)


def _ends_hold_more(values: pd.DataFrame, order: list[str]) -> bool:
    ends = [set(values.loc[values["rung"] == r, "seed"]) for r in (order[0], order[-1])]
    return len(ends[0] & ends[1]) > len(common_seeds(values, order))


def step_tests(
    values: pd.DataFrame, order: list[str], beside: list[str], measures: list[Headline]
) -> pd.DataFrame:
    """One row per (measure, comparison) of the family in the rungs' own worlds: each step and
    the whole on the seeds every rung holds; the whole on every seed the first and last rungs
    hold (WHOLE_ALL), where they hold more; each rung beside against the last rung, on the
    seeds both hold."""
    ladder = values[values["seed"].isin(common_seeds(values, order))]
    tested = family(order, beside, measures, _ends_hold_more(values, order))
    rows = []
    for case in tested[tested["world"] == OWN].to_dict("records"):
        table = ladder if case["kind"] in (STEP, WHOLE) else values
        a, b = _series(table, case["from"], case["key"]), _series(table, case["to"], case["key"])
        rows.append({k: case[k] for k in ("key", "kind", "from", "to")})
        rows[-1].update(step_split.paired_test(b, a))
    return pd.DataFrame(rows)


def split_tests(values: pd.DataFrame, order: list[str], beside: list[str]) -> pd.DataFrame:
    """Each comparison of each competence measure split, in each test world, into its two parts
    (step_split.split_step) on the seeds of the comparison it splits (`step_tests`); a part
    whose rungs were not both tested in that world is in the table without a test (no
    pairs)."""
    ladder = values[values["seed"].isin(common_seeds(values, order))]
    tested = family(order, beside, [], False)
    rows: list[dict] = []
    for case in tested.drop_duplicates(["key", "kind", "from", "to", "world"]).to_dict("records"):
        a, b, key, world = case["from"], case["to"], case["key"], case["world"]
        # The seeds of the step it splits (`step_tests`): a rung beside, all both hold.
        table = ladder if case["kind"] in (STEP, WHOLE) else values
        split = step_split.split_step(
            _series(table, a, key),
            _series(table, b, key),
            _series(table, a, key, world),
            _series(table, b, key, world),
        )
        for part, result in split.items():
            rows.append({**case, "part": part} | result)
    return pd.DataFrame(rows)


def completeness(values: pd.DataFrame, rungs: list[str]) -> pd.DataFrame:
    """What the page checks before its steps mean what they say: one row per rung, the seeds it
    holds in its own world, those of the ladder's seeds (every seed any rung holds) it lacks
    there and in each test world, and how many of its values are not finite (a trial without
    a value for a measure: catches per grasp without a grasp). `complete`: it lacks no seed in
    any world."""
    every = set(values.loc[values["tested"] == OWN, "seed"])
    rows = []
    for rung in rungs:
        mine = values[values["rung"] == rung]
        row: dict = {"rung": rung, "seeds": len(set(mine.loc[mine["tested"] == OWN, "seed"]))}
        lacks = []
        for world in (OWN, *WORLDS):
            missing = sorted(every - set(mine.loc[mine["tested"] == world, "seed"]))
            row[f"missing_{world}"] = missing
            lacks += missing
        row["not_finite"] = int((~np.isfinite(mine["value"])).sum())
        row["complete"] = not lacks
        rows.append(row)
    return pd.DataFrame(rows)


def levels(values: pd.DataFrame) -> pd.DataFrame:
    """Each rung's mean over its trials per measure and test world, with the trials counted."""
    finite = values[np.isfinite(values["value"])]
    grouped = finite.groupby(["rung", "tested", "key"], sort=False)["value"]
    return grouped.agg(mean="mean", n="count").reset_index()


@dataclass(frozen=True)
class LadderRead:
    """What `read_ladder` found: every trial's values (VALUE_COLUMNS), the headline measures,
    each rung's own results, who computed each trial in each world (ladder_data.provenance's
    rows), and the cross-evaluations not found."""

    values: pd.DataFrame
    measures: list[Headline]
    own: dict[str, BatchResults]
    provenance: pd.DataFrame
    missing: list[str]


def read_ladder(rungs: list[Rung], beside: list[Rung] | None = None) -> LadderRead:
    """The rungs in ladder order and those beside it, read. ReportError (one line) for a rung
    that cannot be read, fewer than two rungs, or two rungs of one name."""
    from experiments.report.ladder_data import provenance

    every = [*rungs, *(beside or [])]
    if len(rungs) < 2:
        raise ReportError("a ladder needs at least two rungs (NAME=DIR[:GROUP] each)")
    names = [r.name for r in every]
    if len(set(names)) != len(names):
        raise ReportError(f"two rungs share a name: {', '.join(names)}")
    own = {r.name: rung_results(r) for r in every}
    measures = headline(Geometry.of(own[rungs[0].name]))
    rows, missing, where = [], [], []
    for rung in every:
        rows += values_of(own[rung.name], rung.name, OWN, measures)
        where.append(provenance(own[rung.name], rung.name, OWN))
        competence = [h for h in measures if h.key in COMPETENCE]
        for world in WORLDS:
            try:
                tested = rung_results(rung, world)
            except ReportError as exc:
                missing.append(f"{rung.name} in the {world} world: {exc}")
                continue
            rows += values_of(tested, rung.name, world, competence)
            where.append(provenance(tested, rung.name, world))
    values = pd.DataFrame(rows, columns=VALUE_COLUMNS)
    return LadderRead(values, measures, own, pd.concat(where, ignore_index=True), missing)
