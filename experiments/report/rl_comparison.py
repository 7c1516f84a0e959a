"""Model Babbling against SAC + HER on the same test (docs/rl-baseline.md): a batch of Model
Babbling trials and the baseline runs of the same grasps, seeds, worlds and movements
(`playroom rl-baseline --config`), read as one set of tests over trials.

For every measure (`rl_measures`: entries of the registry, experiments/report/measures.py) one
value per trial or run, the agent the unit; for each grasp, each learner's mean with its 95% t
interval, and SAC's minus Model Babbling's paired by seed (mean, 95% interval, the paired t
test's two-sided p), Holm's correction over every test of the page. The study's own measure
(per pixel, pooled over each learner's runs, against its random reference) is given beside,
with an untrained agent's score. The page: experiments/report/rl_page.py.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable

import numpy as np
import pandas as pd

from experiments.analysis.baseline_results import BaselineResults
from experiments.analysis.geometry import Geometry
from experiments.analysis.results import BatchResults, ReportError
from experiments.analysis.stats import mean_ci, paired_difference, regions
from experiments.analysis.trial_tests import holm, paired_arrays
from experiments.analysis.trial_values import VALUE
from experiments.report.ladder import COMPETENCE, Headline
from experiments.report.measures import registry

MODEL_BABBLING, SAC_HER = "Model Babbling", "SAC + HER"
LEARNERS = (MODEL_BABBLING, SAC_HER)
# Each learner's columns in the tests' table: mb_mean, sac_mean, ...
PREFIX = {MODEL_BABBLING: "mb", SAC_HER: "sac"}
VALUE_COLUMNS = ["grasp", "learner", "seed", "key", "value"]
# What a world is made of: a baseline must have learned in the world of its trial.
WORLD_PARTS = ("world", "voice")
WORLD_TRIAL_PARTS = ("grasp", "preset", "voice", "overrides", "stick_return", "iterations")
# What moved the goal toy after the chosen movement, in ring 1 (what each learner does there).
MOVERS = ("hand", "stick", "caregiver", "push", "none")


def rl_measures(geometry: Geometry) -> list[Headline]:
    """The page's measures: competence per ring; the strategy shares of the project's tests in
    each region (tool: the stick moved, the study's rule); what moved the goal toy in ring 1;
    words within the recognition distance and the names' gap."""
    by_name = {m.name: m for m in registry(geometry)}
    picked = [(name, VALUE, by_name[name].label) for name in COMPETENCE]
    for region in regions(geometry.hand_limit, geometry.stick_limit):
        name = f"strategies_project_study_{region.replace(' ', '_')}"
        for part in ("hand", "tool", "vocal"):
            picked.append((name, part, f"{part} share of the project's tests, {region}"))
    for part in MOVERS:
        label = f"ring 1 tests: the goal toy moved by {part} (after the chosen movement)"
        picked.append(("ring1_goal_moved_by_agent", part, label))
    picked += [
        ("words_within", VALUE, by_name["words_within"].label),
        ("names_vs_distractors", VALUE, by_name["names_vs_distractors"].short),
    ]
    return [
        Headline(name if part == VALUE else f"{name}:{part}", by_name[name], part, label)
        for name, part, label in picked
    ]


def _world(config: dict) -> dict:
    trial = config.get("trial", {})
    return {
        **{k: config.get(k) for k in WORLD_PARTS},
        **{f"trial.{k}": trial.get(k) for k in WORLD_TRIAL_PARTS},
    }


def paired_learners(mb: BatchResults, baselines: BaselineResults) -> BatchResults:
    """The baseline runs as a batch whose groups are the trials' (the grasps), checked to have
    learned in the trials' worlds for as many movements: ReportError naming the first setting
    that differs, or a grasp the trials lack. The runs take the trials' configs (so that the
    study's random reference, which depends on the world alone, is played once per grasp)."""
    for grasp, config in baselines.configs.items():
        if grasp not in mb.configs:
            raise ReportError(
                f"the baselines hold {grasp} runs and the Model Babbling batch has no {grasp} "
                f"trials (it holds {', '.join(mb.groups)})"
            )
        mine, theirs = _world(mb.configs[grasp]), _world(config)
        differ = [k for k in mine if mine[k] != theirs[k]]
        if differ:
            k = differ[0]
            raise ReportError(
                f"the {grasp} baselines did not learn in the trials' world: {k} is "
                f"{theirs[k]!r} for them and {mine[k]!r} for the trials"
            )
    return dataclasses.replace(
        baselines.as_batch(), configs={g: mb.configs[g] for g in baselines.configs}
    )


def learner_values(mb: BatchResults, sac: BatchResults, measures: list[Headline]) -> pd.DataFrame:
    """Rows (grasp, learner, seed, key, value): each measure's value per trial and per run, on
    the grasps both learners hold."""
    rows = []
    for grasp in [g for g in mb.groups if g in sac.groups]:
        for learner, results in ((MODEL_BABBLING, mb), (SAC_HER, sac)):
            mine = results.select(grasp)
            for h in measures:
                frame = h.measure.values(mine)
                for seed, value in zip(frame["seed"], frame[h.part], strict=True):
                    rows.append((grasp, learner, int(seed), h.key, float(value)))
    if not rows:
        raise ReportError(
            f"the Model Babbling batch ({', '.join(mb.groups)}) and the baselines "
            f"({', '.join(sac.groups)}) share no grasp"
        )
    return pd.DataFrame(rows, columns=VALUE_COLUMNS)


def _series(values: pd.DataFrame, grasp: str, learner: str, key: str) -> pd.Series:
    mine = values[(values["grasp"] == grasp) & (values["learner"] == learner)]
    mine = mine[mine["key"] == key]
    return mine.set_index("seed")["value"]


def learner_tests(values: pd.DataFrame, measures: list[Headline]) -> pd.DataFrame:
    """One row per grasp and measure: each learner's mean, 95% t interval and number of
    agents with a value; SAC's minus Model Babbling's paired by seed (mean, interval, paired
    t p, pairs); Holm's adjustment over every test of the table (`holm_p`)."""
    rows = []
    for grasp in dict.fromkeys(values["grasp"]):
        for h in measures:
            row: dict = {"grasp": grasp, "key": h.key, "label": h.label, "kind": h.measure.kind}
            sides = {name: _series(values, grasp, name, h.key) for name in LEARNERS}
            for name, prefix in PREFIX.items():
                mine = sides[name].to_numpy(dtype=float)
                mean, low, high = mean_ci(mine)  # over its finite values
                row |= {f"{prefix}_mean": mean, f"{prefix}_low": low, f"{prefix}_high": high}
                row[f"{prefix}_n"] = int(np.isfinite(mine).sum())
            x, y = paired_arrays(sides[SAC_HER], sides[MODEL_BABBLING])
            difference, low, high, p = paired_difference(x, y)
            row |= {"difference": difference, "low": low, "high": high, "p": p}
            rows.append(row | {"n_pairs": len(x)})
    table = pd.DataFrame(rows)
    table["holm_p"] = holm(table["p"].astype(float).tolist())
    return table


def study_scores(
    mb: BatchResults, sac: BatchResults, study_numbers: Callable[[BatchResults], dict]
) -> dict[str, dict[str, dict]]:
    """grasp -> learner -> the study's summary of the learner's tests (pooled over its runs,
    per pixel, against the grasp's random reference) with an untrained agent's score beside
    (`study_numbers`: experiments/measure/for_reports.room_measures' own, which keeps each
    reference; Model Babbling's first, so that the runs read the reference it kept)."""
    out: dict[str, dict[str, dict]] = {}
    for learner, results in ((MODEL_BABBLING, mb), (SAC_HER, sac)):
        for grasp, numbers in study_numbers(results).items():
            out.setdefault(grasp, {})[learner] = numbers
    return out
