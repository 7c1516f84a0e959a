"""The paper's published numbers (`experiments/report/data/paper.json`) and the table that sets a
batch's numbers beside them.

The numbers are data, not code, so that each carries where the paper states it (section,
figure), the paper's own words and how many runs it came from (the text's 500, or the 100 of
the study's notebooks for the competence map and Fig. 4); the report shows the `text` of
each with its run count, and lists the sources under the table. The file ships in the
package (package-data) and is read with importlib.resources, so an installed wheel finds it
too.
"""

from __future__ import annotations

import functools
import json
from dataclasses import dataclass
from importlib import resources
from pathlib import Path
from typing import Any

from experiments.analysis.geometry import Geometry
from experiments.analysis.results import BatchResults
from experiments.analysis.stats import DISTANCE_ONE
from experiments.analysis.study_maps import BOOTSTRAP_SAMPLES
from experiments.analysis.study_summary import FULL_COVERAGE, RANDOM_COMMANDS_PER_RING
from experiments.analysis.trial_tests import one_sample_test
from experiments.analysis.trial_values import VALUE, names_gap
from experiments.report.pages import Table, ci_text, num, p_value, pct, shares_text

PAPER_FILE = "paper.json"
# A number the paper does not give (per ring competence): said so, not left blank.
NOT_PUBLISHED = "not published"
FIELDS = ("value", "text", "source", "quote", "runs", "runs_source")


@dataclass(frozen=True)
class PaperNumber:
    """One published number. value: a fraction in [0, 1], a word distance, a p value, or a
    dict of them ([low, high] where the paper gives a range); text: what the report shows;
    source: where in the paper; quote: the paper's words; runs: how many runs it was computed
    from; runs_source: where that count comes from."""

    key: str
    value: Any
    text: str
    source: str
    quote: str
    runs: int
    runs_source: str

    @property
    def cell(self) -> str:
        """The text with its run count, as a table shows it: the paper's numbers come from
        different numbers of runs, so no column header can say it for all of them."""
        return f"{self.text} (from {self.runs} runs)"


def _read(path: Path | None) -> dict:
    if path is None:
        raw = resources.files("experiments.report").joinpath("data", PAPER_FILE).read_text("utf-8")
    else:
        raw = Path(path).read_text("utf-8")
    return json.loads(raw)


def load(path: Path | None = None) -> dict[str, PaperNumber]:
    """The numbers of `path` (default: the packaged data/paper.json), by key. ValueError
    naming the key when an entry lacks one of FIELDS or its runs is not a positive integer."""
    numbers = {}
    for key, entry in _read(path)["numbers"].items():
        missing = [f for f in FIELDS if not entry.get(f)]
        if missing:
            # A number without its source is what this file exists to prevent.
            raise ValueError(f"{PAPER_FILE}: {key} lacks {', '.join(missing)}")
        if not isinstance(entry["runs"], int) or isinstance(entry["runs"], bool):
            raise ValueError(f"{PAPER_FILE}: {key} runs must be a whole number of runs")
        numbers[key] = PaperNumber(key=key, **{f: entry[f] for f in FIELDS})
    return numbers


@functools.cache
def published() -> dict[str, PaperNumber]:
    """The packaged numbers, read once per process."""
    return load()


@functools.cache
def reference() -> str:
    """The paper's citation, as the packaged file gives it."""
    return _read(None)["reference"]


def paper_header(groups: list[str], prefix: str = "") -> list[str]:
    """Header of the paper table: result, the paper (each cell says its runs: they differ from
    number to number), then one column per group (each label after `prefix`, e.g. "this
    batch: ")."""
    return ["result", "paper", *[f"{prefix}{g}" for g in groups]]


def paper_rows(results: BatchResults, numbers: dict, geometry: Geometry) -> list[list[str]]:
    """[result, paper, value of group 1, value of group 2, ...], one list per row.
    `numbers`: `analysis.stats.summarise_batch` of `results`."""
    paper = published()
    g = results.groups
    comp, strat, vocal = numbers["competence"], numbers["strategies"], numbers["vocal"]

    def competence_of(scope: str) -> list[str]:
        return [ci_text(comp[(comp["group"] == x) & (comp["scope"] == scope)].iloc[0]) for x in g]

    def shares_of(region: str) -> list[str]:
        return [
            shares_text(strat[(strat["group"] == x) & (strat["region"] == region)].iloc[0])
            for x in g
        ]

    h, s, t = geometry.hand_limit, geometry.stick_limit, geometry.threshold
    return [
        [
            "Normalised competence, all rings (mean over trials)",
            paper["competence_all"].cell,
            *competence_of("all"),
        ],
        [f"… ring 1 (toy within hand reach, d < {h:g} m)", NOT_PUBLISHED, *competence_of("ring1")],
        [f"… ring 2 ({h:g} ≤ d < {s:g} m)", NOT_PUBLISHED, *competence_of("ring2")],
        [f"… ring 3 ({s:g} ≤ d ≤ 1 m)", NOT_PUBLISHED, *competence_of("ring3")],
        [
            f"Strategy hand / tool / vocal, centre region (d < {h:g} m)",
            paper["strategy_centre"].cell,
            *shares_of("centre"),
        ],
        [
            f"Strategy hand / tool / vocal, between hand and stick limits ({h:g} ≤ d < {s:g} m)",
            paper["strategy_between_limits"].cell,
            *shares_of("between limits"),
        ],
        [
            f"Strategy hand / tool / vocal, at distance 1 (d ≥ {DISTANCE_ONE:g} m)",
            paper["strategy_distance_1"].cell,
            *shares_of("distance 1"),
        ],
        *_study_rows(g, numbers.get("study", {}), paper),
        [
            f"Words imitated within {t:g} (best distance)",
            paper["words_below_threshold"].cell,
            *[f"{pct(vocal[x]['share_below'])} (of {vocal[x]['n_words']} words)" for x in g],
        ],
        [
            "Median best distance, toy names",
            paper["median_names"].cell,
            *[num(vocal[x]["median_names"]) for x in g],
        ],
        [
            "Median best distance, distractors",
            paper["median_distractors"].cell,
            *[num(vocal[x]["median_distractors"]) for x in g],
        ],
        [
            "Mann-Whitney U, names vs distractors "
            "(two-sided p: the one-sided p doubled, as the study did; on the words of all "
            "trials pooled, as the study did, so treating words as independent)",
            paper["mann_whitney_p"].cell,
            *[f"U = {num(vocal[x]['u'], 1)}, {p_value(vocal[x]['p'])}" for x in g],
        ],
        [
            "Names vs distractors over trials, the agent the unit: each trial's median best "
            "distance of its distractors minus its names, mean over trials, one-sample t "
            "against 0 (two-sided)",
            "(the study tested pooled words only)",
            *[_names_gap_text(results.select(x)) for x in g],
        ],
    ]


def _names_gap_text(results: BatchResults) -> str:
    """A group's names gap over trials: mean, t p and the trials behind it."""
    test = one_sample_test(names_gap(results).set_index("trial")[VALUE])
    return f"{num(test.difference, 3)}, {p_value(test.p)} (n={test.n[0]} trials)"


def _study_rows(groups: list[str], study: dict, paper: dict) -> list[list[str]]:
    """The paper's competence and strategy numbers beside the study's own measure of each
    group (experiments/measure/study_measure.py); none if no group has the study's tests."""
    if not study:
        return []

    def of(group: str, pick) -> str:
        return pick(study[group]) if group in study else "not measured"

    def interval(numbers: dict, *keys: str) -> str:
        """ " [a, b]" of the bias-corrected bootstrap over runs; " [no interval]" where it was
        computed but none contains the estimate; nothing where it was not computed."""
        if "intervals" not in numbers:
            return ""
        bounds = numbers["intervals"]
        for key in keys:
            bounds = bounds.get(key)
        return " [no interval]" if bounds is None else f" [{pct(bounds[0])}, {pct(bounds[1])}]"

    def competence(numbers: dict) -> str:
        return pct(numbers["competence"]["all"]) + interval(numbers, "competence_all")

    def untrained(numbers: dict) -> str:
        if "untrained" not in numbers:
            return "not measured"
        still = numbers["untrained"]
        return (
            f"{pct(still['competence']['all'])}; {still['same_as_untrained']} of "
            f"{still['trials']} trials untrained in every test, "
            f"{pct(still['tests_as_untrained'])} of their tests"
        )

    def shares(region: str):
        def text(numbers: dict) -> str:
            share = numbers["strategy_share"].get(region, {})
            cells = " / ".join(
                pct(share.get(k, 0.0)) + interval(numbers, "strategy_share", region, k)
                for k in ("hand", "tool", "vocal")
            )
            coverage = numbers.get("coverage", 1.0)
            if coverage < FULL_COVERAGE:  # the notebook's renormalisation needs full coverage
                cells += (
                    f" (tests in only {pct(coverage)} of the disk's pixels: shares sum below 100%)"
                )
            return cells

        return text

    label = "as the study computed it"
    commands = next(iter(study.values()))["reference_commands_per_ring"]
    return [
        [
            f"Competence, all rings, {label} (mean per-pixel max(0, 1 - agent / random); "
            f"random reference of {commands} commands per ring (the batch profile's "
            "study_reference_commands, or --study-reference-commands), the study's "
            f"{RANDOM_COMMANDS_PER_RING}; 95% bias-corrected (BC) bootstrap intervals over "
            f"{BOOTSTRAP_SAMPLES} resamples of the runs, given where the tests cover "
            f"{pct(FULL_COVERAGE)} of the disk's pixels or more and the estimate lies within "
            "the central 95% of its resamples)",
            paper["competence_all"].cell,
            *[of(x, competence) for x in groups],
        ],
        [
            "… an agent that never learned, as the study computed it (no data in any model: "
            "the arm at rest in every test, the same placements and random reference; a random "
            "command now and then knocks the toy away, stillness does not), and the trials "
            "that scored exactly so (untrained), and the share of tests that did",
            NOT_PUBLISHED,
            *[of(x, untrained) for x in groups],
        ],
        *[
            [f"… ring {r}, {label}", NOT_PUBLISHED]
            + [of(x, lambda n, r=r: pct(n["competence"][f"ring{r}"])) for x in groups]
            for r in (1, 2, 3)
        ],
        [
            f"Strategy hand / tool / vocal, centre (Fig. 4's curve, x < 0.6 m), {label}",
            paper["strategy_centre"].cell,
            *[of(x, shares("centre")) for x in groups],
        ],
        [
            f"Strategy hand / tool / vocal, between the limits (0.6 ≤ x < 0.85 m), {label}",
            paper["strategy_between_limits"].cell,
            *[of(x, shares("between_limits")) for x in groups],
        ],
        [
            f"Strategy hand / tool / vocal, distance 1 (the curve's last bin), {label}",
            paper["strategy_distance_1"].cell,
            *[of(x, shares("distance_1")) for x in groups],
        ],
    ]


def paper_table(results: BatchResults, numbers: dict, geometry: Geometry, prefix: str) -> Table:
    """The paper table of `results` (see paper_rows), group columns labelled `prefix` + group."""
    return Table(paper_header(results.groups, prefix), paper_rows(results, numbers, geometry))
