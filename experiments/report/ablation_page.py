"""The ablation table's page (ablations.md): the table of experiments/report/ablations.py, each
paired t with the signed-rank p beside it, the table's one family of tests and how many of
them survive Holm's correction under each kind of p, and every cell whose star differs between
the two (experiments/report/ablation_tests.py); a link to the per-trial data beside it
(experiments/report/ablation_data.py)."""

from __future__ import annotations

import math

from experiments.analysis import step_split
from experiments.analysis.stats import STRATEGIES
from experiments.analysis.trial_tests import ALPHA, survives
from experiments.report import ablation_data, ablation_tests
from experiments.report.ablation_tests import AblationRow
from experiments.report.measures import GAP, Measure
from experiments.report.pages import p_value, survive

# The study's regions, in the order the table shows them (experiments.measure.study_measure).
STUDY_REGIONS = ("centre", "between_limits", "distance_1")


def _percent(value: float, digits: int = 0) -> str:
    return "n/a" if not math.isfinite(value) else f"{100 * value:.{digits}f}%"


def _shares(row: AblationRow, region: str) -> str:
    shares = row.study_strategies.get(region)
    if not shares:
        return "n/a"
    return "/".join(f"{100 * shares.get(s, 0.0):.0f}" for s in STRATEGIES)


def _number(value: float, form: str) -> str:
    return "n/a" if not math.isfinite(value) else format(value, form)


def table_lines(rows: list[AblationRow], measures: tuple[Measure, ...]) -> list[str]:
    """The table of `ablations.ablation_rows` in Markdown, `measures` its registry columns."""
    gaps = [m for m in measures if m.test == GAP]
    head = [
        "configuration",
        "trials",
        "competence, study's measure",
        "hand/tool/vocal centre",
        "between limits",
        "distance 1",
        *(ablation_tests.header(m) for m in measures),
        *(ablation_tests.gap_header(m) for m in gaps),
        "median names / distractors (pooled words)",
        "names vs distractors pooled over words (Mann-Whitney two-sided p, one-sided doubled as "
        "the study; treats words as independent)",
    ]
    lines = ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    for row in rows:
        cells = [
            row.label,
            str(row.n_trials),
            _percent(row.study_competence),
            *(_shares(row, region) for region in STUDY_REGIONS),
            *(ablation_tests.cell(m, row.measures[m.name]) for m in measures),
            *(ablation_tests.within_cell(row.measures[m.name]) for m in gaps),
            f"{_number(row.median_names, '.2f')} / {_number(row.median_distractors, '.2f')}",
            _number(row.pooled_names_vs_distractors_p_two_sided, ".2g"),
        ]
        lines.append("| " + " | ".join(cells) + " |")
    return lines


def family_lines(rows: list[AblationRow], measures: tuple[Measure, ...]) -> list[str]:
    """The family, as declared (ablation_tests.FAMILY), with its counts."""
    n = ablation_tests.count_tests([row.measures for row in rows], measures)
    return [
        f"One family of {n['family']} tests, fixed by the table's rows and measures before any "
        "value was read (`experiments/report/ablation_tests.py` FAMILY):",
        "",
        *(f"- {part}" for part in ablation_tests.FAMILY),
        "",
        f"{n['made']} of them could be made (a comparison with fewer than 2 pairs, or whose "
        "every pair is equal, has no p and does not count in Holm's m). Holm's correction at "
        f"{ALPHA:g} over them: {survive(n['t'])} with the t, {n['rank']} with the Wilcoxon "
        "signed-rank test.",
    ]


def disagreement_lines(rows: list[AblationRow], measures: tuple[Measure, ...]) -> list[str]:
    """Every cell whose Holm star differs between the t and the signed-rank test."""
    tests = ablation_tests.declared_tests([row.measures for row in rows], measures)
    label = {m.name: m.short or m.label for m in measures}
    lines = []
    for r in tests.to_dict("records"):
        if not step_split.stars_differ(r):
            continue
        starred = "the t" if survives(float(r["p_holm"])) else "the signed-rank test"
        lines.append(
            f"- {rows[r['row']].label}, {label[r['measure']]} ({r['test']}): starred by "
            f"{starred} only ({p_value(float(r['p']))}; rank {p_value(float(r['p_rank']))})"
        )
    return lines or ["None: every star of the table is the same under both tests."]


def markdown(rows: list[AblationRow], measures: tuple[Measure, ...]) -> str:
    """The page: the table, the tests' counts, the family and the stars' disagreements."""
    n = ablation_tests.count_tests([row.measures for row in rows], measures)
    lines = [
        *table_lines(rows, measures),
        "",
        f"{n['made']} tests over trials, the agent the unit, in one family (below); * after a p "
        f"where it survives Holm's correction over it (family-wise α = {ALPHA:g}) for its kind "
        f"of p: {n['t']} with the paired t (or the one-sample t against 0), {n['rank']} with the "
        "Wilcoxon signed-rank test of the same differences (or values). The last column pools "
        "the words of every trial and is not counted.",
        "",
        f"Every trial's values, with the machine and commit that computed it: "
        f"[{ablation_data.FILE}]({ablation_data.FILE}), from which every number of the tests "
        "can be computed again.",
        "",
        "## The family of tests",
        "",
        *family_lines(rows, measures),
        "",
        "## Where the t and the signed-rank test disagree on a star",
        "",
        *disagreement_lines(rows, measures),
    ]
    return "\n".join(lines) + "\n"
