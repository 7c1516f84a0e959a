"""The page of Model Babbling against SAC + HER (`playroom rl-compare MB_DIR SAC_DIR --out DIR`):
the tests of experiments/report/rl_comparison.py written as one unit into DIR: rl-compare.md
(the tables), rl-compare.csv (every test, unrounded), rl-compare.json (every agent's values,
every test, the study's measure, where each side was computed) and rl-compare.png (competence
per ring, every agent a dot)."""

from __future__ import annotations

import math
import os
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pandas as pd
from matplotlib.figure import Figure

from experiments.analysis.baseline_results import collect_baselines
from experiments.analysis.geometry import Geometry
from experiments.analysis.results import BatchResults, check_out_dir, collect
from experiments.analysis.trial_tests import survives
from experiments.report import rl_comparison as rl
from experiments.report.figures import png_bytes
from experiments.report.ladder import COMPETENCE
from experiments.report.ladder_page import json_records
from experiments.report.pages import machines_text, p_value, seeds_text, survive
from experiments.report.paired_text import level_text, signed_text
from experiments.trial_dir import storage

FILES = ("rl-compare.csv", "rl-compare.json", "rl-compare.png", "rl-compare.md")
COLOURS = {rl.MODEL_BABBLING: "tab:blue", rl.SAC_HER: "tab:orange"}
SCOPES = [k.removeprefix("competence_").replace("ring", "ring ") for k in COMPETENCE]


def _side(kind: str, row: dict, prefix: str) -> str:
    mean, n = row[f"{prefix}_mean"], int(row[f"{prefix}_n"])
    if not math.isfinite(mean):
        return f"n/a ({n})"
    low, high = row[f"{prefix}_low"], row[f"{prefix}_high"]
    interval = f" [{level_text(kind, low)}, {level_text(kind, high)}]"
    return f"{level_text(kind, mean)}{interval if math.isfinite(low) else ''} ({n})"


def _difference(row: dict) -> str:
    kind, n = row["kind"], int(row["n_pairs"])
    if not math.isfinite(row["difference"]):
        return f"n/a ({n} pairs)"
    text = signed_text(kind, row["difference"])
    if math.isfinite(row["low"]):
        text += f" [{signed_text(kind, row['low'])}, {signed_text(kind, row['high'])}]"
    if n < 2:
        return f"{text}, untested: fewer than 2 pairs ({n})"
    if not math.isfinite(row["p"]):
        return f"{text}, untested: every pair equal ({n})"
    mark = " *" if survives(row["holm_p"]) else ""
    return f"{text}, {p_value(row['p'])}{mark} ({n})"


def _settings_lines(mb: BatchResults, sac: BatchResults, grasps: list[str]) -> list[str]:
    lines = [
        "| grasp | learner | agents | seeds | movements each | computed on |",
        "|---|---|---|---|---|---|",
    ]
    for grasp in grasps:
        for learner, results in zip(rl.LEARNERS, (mb, sac), strict=True):
            mine = results.select(grasp)
            seeds = sorted(int(s) for s in mine.trials["seed"])
            movements = sorted({int(m) for m in mine.trials["iterations"]})
            lines.append(
                f"| {grasp} | {learner} | {len(seeds)} | {seeds_text(seeds)} | "
                f"{', '.join(map(str, movements))} | {machines_text(mine)} |"
            )
    return lines


def _percent(x: float | None) -> str:
    if x is None or not math.isfinite(x):
        return "n/a"
    return "< 1%" if 0 < x < 0.01 else f"{100 * x:.0f}%"


def _study_lines(study: dict[str, dict[str, dict]]) -> list[str]:
    lines = [
        "| grasp | learner | all [95% BC bootstrap over agents] / ring 1 / ring 2 / ring 3 | "
        "pixels with a test | an untrained agent, all rings |",
        "|---|---|---|---|---|",
    ]
    for grasp, learners in study.items():
        for learner, numbers in learners.items():
            c = numbers["competence"]
            interval = (numbers.get("intervals") or {}).get("competence_all")
            whole = _percent(c.get("all"))
            if interval:
                whole += f" [{_percent(interval[0])}, {_percent(interval[1])}]"
            rings = " / ".join(_percent(c.get(k)) for k in ("ring1", "ring2", "ring3"))
            still = numbers.get("untrained", {}).get("competence", {}).get("all")
            lines.append(
                f"| {grasp} | {learner} | {whole} / {rings} | "
                f"{_percent(numbers.get('coverage'))} | {_percent(still)} |"
            )
    return lines


def markdown(
    command: str,
    mb: BatchResults,
    sac: BatchResults,
    tests: pd.DataFrame,
    study: dict[str, dict[str, dict]],
) -> str:
    grasps = list(dict.fromkeys(tests["grasp"]))
    n_tests = int(np.isfinite(tests["p"].to_numpy(dtype=float)).sum())
    n_kept = int(sum(survives(p) for p in tests["holm_p"]))
    lines = [
        "# Model Babbling against SAC + HER, on the same test",
        "",
        f"*`{command}`*",
        "",
        "Each agent is one trial of Model Babbling or one SAC + HER run (three toy policies) of "
        "the same grasp, seed, world and number of movements, tested by the project's measure on "
        "the same placements (docs/rl-baseline.md). Means over agents with their 95% t "
        "intervals, agents in brackets; the difference is SAC + HER's minus Model Babbling's, "
        "paired by seed, with the paired t test's two-sided p and its pairs. Shares in percent "
        f"(points for differences). {n_tests} tests; Holm's correction over all of them, "
        f"{survive(n_kept)} (marked *, α = 0.05).",
        "",
        *_settings_lines(mb, sac, grasps),
        "",
    ]
    for grasp in grasps:
        lines += [
            f"## {grasp}",
            "",
            f"| measure | {rl.MODEL_BABBLING} | {rl.SAC_HER} | SAC + HER − Model Babbling |",
            "|---|---|---|---|",
        ]
        for row in tests[tests["grasp"] == grasp].to_dict("records"):
            lines.append(
                f"| {row['label']} | {_side(row['kind'], row, 'mb')} | "
                f"{_side(row['kind'], row, 'sac')} | {_difference(row)} |"
            )
        lines.append("")
    lines += [
        "## The study's measure",
        "",
        "Per pixel of the disk, pooled over each learner's agents, against the grasp's random "
        "reference, as the study computed it (docs/protocol.md §10); beside it, what it gives "
        "an agent that never learned (it leaves the arm at rest in every test). No interval "
        "below 90% of the disk's pixels holding a test.",
        "",
        *_study_lines(study),
        "",
        "![Normalised competence per ring, every agent a dot, means with their 95% "
        "intervals](rl-compare.png)",
        "",
    ]
    return "\n".join(lines)


def figure(values: pd.DataFrame, tests: pd.DataFrame) -> Figure:
    """One panel per grasp: each learner's agents' competence per ring (dots), their mean and
    95% interval (bar); 0 is a random command's level."""
    grasps = list(dict.fromkeys(values["grasp"]))
    fig = Figure(figsize=(4.2 * len(grasps), 3.4), layout="constrained")
    axes = np.atleast_1d(fig.subplots(1, len(grasps), sharey=True, squeeze=False)[0])
    rng = np.random.default_rng(0)  # the dots' jitter only
    for ax, grasp in zip(axes, grasps, strict=True):
        for j, learner in enumerate(rl.LEARNERS):
            offset = -0.18 if j == 0 else 0.18
            for i, key in enumerate(COMPETENCE):
                mine = values[
                    (values["grasp"] == grasp)
                    & (values["learner"] == learner)
                    & (values["key"] == key)
                ]["value"].to_numpy(dtype=float)
                x = i + offset + rng.uniform(-0.05, 0.05, len(mine))
                ax.scatter(x, 100 * mine, s=8, color=COLOURS[learner], alpha=0.6, lw=0)
                (row,) = tests[(tests["grasp"] == grasp) & (tests["key"] == key)].to_dict("records")
                prefix = rl.PREFIX[learner]
                mean, low, high = (row[f"{prefix}_{k}"] for k in ("mean", "low", "high"))
                if math.isfinite(low):
                    err = 100 * np.array([[mean - low], [high - mean]])
                    ax.errorbar(i + offset, 100 * mean, yerr=err, color="k", capsize=3, lw=1)
                ax.plot(
                    [i + offset - 0.12, i + offset + 0.12],
                    [100 * mean] * 2,
                    color=COLOURS[learner],
                    lw=2,
                    label=learner if i == 0 else None,
                )
        ax.axhline(0, color="k", lw=0.5)
        ax.set_xticks(range(len(SCOPES)), SCOPES)
        ax.set_title(f"{grasp} backend", fontsize=9)
    axes[0].set_ylabel("normalised competence (%), 0 = random")
    axes[0].legend(fontsize=7)
    return fig


def write_rl_compare(
    mb_dir: str | os.PathLike,
    sac_dir: str | os.PathLike,
    out_dir: str | os.PathLike,
    command: str,
    study_numbers: Callable[[BatchResults], dict],
) -> Path:
    """Read, test and write (module docstring); nothing is written unless all of it is
    computed. Returns the page's path."""
    out = Path(out_dir)
    check_out_dir(out)
    mb = collect(mb_dir)
    sac = rl.paired_learners(mb, collect_baselines(sac_dir))
    measures = rl.rl_measures(Geometry.of(mb))
    values = rl.learner_values(mb, sac, measures)
    tests = rl.learner_tests(values, measures)
    study = rl.study_scores(mb, sac, study_numbers)
    record = {
        "command": command,
        "model_babbling": str(mb_dir),
        "sac_her": str(sac_dir),
        "measures": {h.key: {"label": h.label, "kind": h.measure.kind} for h in measures},
        "values": json_records(values),
        "tests": json_records(tests),
        "study": storage.finite_or_null(study),
        "computed_on": {
            rl.MODEL_BABBLING: machines_text(mb),
            rl.SAC_HER: machines_text(sac),
        },
    }
    files = {
        "rl-compare.csv": tests.to_csv(index=False).encode(),
        "rl-compare.json": storage.json_bytes(record),
        "rl-compare.png": png_bytes(figure(values, tests)),
        "rl-compare.md": markdown(command, mb, sac, tests, study).encode(),
    }
    return storage.write_files(out, files)[-1]
