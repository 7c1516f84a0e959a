"""Reports of a batch of trials: its results beside the paper's (`playroom report DIR`) and two
batches side by side (`playroom compare DIR_A DIR_B --out DIR`).

A batch directory holds trial directories (any sub-directory with `config.json`), each
evaluated (`eval.json`, `competence.parquet`, `vocal.parquet`, written by
`experiments.evaluation`). Trials form groups by grasp backend and babbling mode; within a
group every setting but the seed must agree, or the report refuses to pool them.

Outputs are PNG figures (`experiments.figures`) and one self-contained HTML page with the
figures embedded as data URIs. Everything is computed and rendered in memory first and each
file is then written atomically, so a failing report leaves nothing half-written.
"""

from __future__ import annotations

import base64
import dataclasses
import html
import json
import math
import os
import tempfile
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd
from scipy import stats

from experiments import figures, storage
from experiments.evaluation import COMPETENCE_FILE, EVAL_FILE, VOCAL_FILE
from experiments.trial import CONFIG_FILE, read_log

REPORT_FILE = "report.html"
COMPARISON_FILE = "comparison.html"
TIMING_FILE = "timing.json"
COMPETENCE_SCOPES = ("all", "ring1", "ring2", "ring3")
# Toys at least this far from the arm's base count as "at distance 1" (paper, Fig. 4).
DISTANCE_ONE = 0.95
# Developmental curves have about this many points per trial, each a window of iterations.
CURVE_POINTS = 40
# The paper's published numbers (protocol.md, "Evaluation after learning").
PAPER_COMPETENCE = 0.46


class ReportError(Exception):
    """A batch that cannot be reported on; the message (one line) says why."""


# --------------------------------------------------------------------------------------------
# Collecting a batch
# --------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class BatchResults:
    """Every table of a batch, one row per trial / test / word / curve point, each row labelled
    with its trial (`trial`, the directory name), `group` (grasp, plus babbling when a batch
    mixes modes) and `seed`.

    - trials: eval.json's numbers (competence_all, competence_ring1..3, share_below_threshold,
      median_names, median_distractors, ...), diverged iterations, and timing.json's
      seconds / timed_iterations (NaN when not recorded).
    - competence: competence.parquet rows (ring, placement, toy, x, y, distance, strategy,
      error, random_error, ...).
    - vocal: vocal.parquet rows (word, is_name, best_distance).
    - curves: long table (iteration, metric, value) of developmental curves: tool_use (share of
      arm movements that moved a toy with the stick), stick_grasp (share of arm movements),
      word_recognised (share of vocal movements), best_distance_names and
      best_distance_distractors (mean best distance so far of the trial's names/distractors).
    - configs: group -> the group's common config (trial.seed removed).
    """

    batch_dir: Path
    trials: pd.DataFrame
    competence: pd.DataFrame
    vocal: pd.DataFrame
    curves: pd.DataFrame
    configs: dict[str, dict]

    @property
    def groups(self) -> list[str]:
        return list(self.configs)

    def select(self, group: str) -> BatchResults:
        """The results of one group only."""
        keep = {name: table[table["group"] == group] for name, table in self._tables().items()}
        return dataclasses.replace(self, **keep, configs={group: self.configs[group]})

    def relabel(self, mapping: dict[str, str]) -> BatchResults:
        """The same results with groups renamed (to tell two batches apart)."""
        tables = {}
        for name, table in self._tables().items():
            table = table.copy()
            table["group"] = table["group"].map(lambda g: mapping.get(g, g))
            tables[name] = table
        configs = {mapping.get(g, g): c for g, c in self.configs.items()}
        return dataclasses.replace(self, **tables, configs=configs)

    def _tables(self) -> dict[str, pd.DataFrame]:
        return {
            "trials": self.trials,
            "competence": self.competence,
            "vocal": self.vocal,
            "curves": self.curves,
        }


def _read_json(path: Path) -> Any:
    try:
        return storage.read_json(path)
    except storage.CorruptFileError as exc:
        raise ReportError(str(exc)) from None


def _read_table(path: Path) -> pd.DataFrame:
    if not path.exists():
        raise ReportError(f"{path} is missing: evaluate the trial again (`playroom eval`)")
    try:
        return storage.read_table(path)
    except storage.CorruptFileError as exc:
        raise ReportError(str(exc).replace("\n", " ")) from None


def _flatten(config: dict, prefix: str = "") -> dict[str, Any]:
    out = {}
    for key, value in config.items():
        if isinstance(value, dict):
            out.update(_flatten(value, f"{prefix}{key}."))
        else:
            out[f"{prefix}{key}"] = value
    return out


def _shared_config(config: dict) -> dict:
    """A trial's config without its seed: what must agree within a group."""
    shared = json.loads(json.dumps(config))
    shared.get("trial", {}).pop("seed", None)
    return shared


def _names(paths: list[Path], limit: int = 5) -> str:
    shown = ", ".join(p.name for p in paths[:limit])
    return shown + (f" and {len(paths) - limit} more" if len(paths) > limit else "")


def _trial_dirs(batch_dir: Path) -> list[Path]:
    if not batch_dir.is_dir():
        raise ReportError(f"{batch_dir} is not a directory")
    dirs = sorted(d for d in batch_dir.iterdir() if d.is_dir() and (d / CONFIG_FILE).exists())
    if not dirs:
        raise ReportError(
            f"{batch_dir} holds no trials (no sub-directory with {CONFIG_FILE}); "
            "run `playroom batch` or `playroom run` first"
        )
    missing = [d for d in dirs if not (d / EVAL_FILE).exists()]
    if missing:
        raise ReportError(
            f"{len(missing)} of {len(dirs)} trials in {batch_dir} have no {EVAL_FILE} "
            f"(not evaluated): {_names(missing)}; run `playroom eval` on them"
        )
    return dirs


def _group_label(grasp: str, babbling: str, mixed_babbling: bool) -> str:
    return f"{grasp} {babbling}" if mixed_babbling else grasp


def _check_group(label: str, dirs: list[Path], configs: list[dict], evals: list[dict]) -> None:
    """Every setting but the seed agrees; seeds are distinct; every trial was evaluated at its
    end on the same number of placements."""
    reference = _flatten(_shared_config(configs[0]))
    for d, config in zip(dirs[1:], configs[1:], strict=True):
        flat = _flatten(_shared_config(config))
        for key in sorted(set(reference) | set(flat)):
            if reference.get(key) != flat.get(key):
                raise ReportError(
                    f"trials of mismatched configs in group {label}: {dirs[0].name} and "
                    f"{d.name} differ in {key} ({reference.get(key)!r} != {flat.get(key)!r})"
                )
    seen: dict[int, Path] = {}
    for d, config in zip(dirs, configs, strict=True):
        seed = config["trial"]["seed"]
        if seed in seen:
            raise ReportError(
                f"seed {seed} appears twice in group {label} ({seen[seed].name}, {d.name}): "
                "a trial copied twice would count double"
            )
        seen[seed] = d
    for d, config, summary in zip(dirs, configs, evals, strict=True):
        if summary.get("evaluated_at_iteration") != config["trial"]["iterations"]:
            raise ReportError(
                f"{d.name} was evaluated at iteration {summary.get('evaluated_at_iteration')} "
                f"of {config['trial']['iterations']}: finish the trial and evaluate it again"
            )
    placements = {s.get("n_placements") for s in evals}
    if len(placements) > 1:
        raise ReportError(
            f"trials of group {label} were evaluated on different numbers of placements "
            f"({sorted(placements, key=str)}): evaluate them again with the same --placements"
        )


def _curve_rows(
    log: pd.DataFrame, words: pd.DataFrame, iterations: int, names: set[str]
) -> pd.DataFrame:
    """A trial's developmental curves from its logs: rates in windows of iterations (about
    CURVE_POINTS of them), best word distances wherever the words log has a row."""
    window = max(50, round(iterations / CURVE_POINTS / 50) * 50)
    end = (log["iteration"].to_numpy() // window + 1) * window
    arm = log["motor_space"] == "arm"
    voice = log["motor_space"] == "voice"
    toy_columns = [c for c in log.columns if c.startswith("toy") and c.endswith("_moved_by")]
    by_stick = (log[toy_columns] == "stick").any(axis=1)
    frame = pd.DataFrame(
        {
            "end": np.minimum(end, iterations),
            "arm": arm,
            "voice": voice,
            "tool_use": by_stick & arm,
            "stick_grasp": log["stick_grasped"].astype(bool) & arm,
            "word_recognised": (log["word_recognised"] != "") & voice,
        }
    )
    sums = frame.groupby("end").sum()
    with np.errstate(invalid="ignore", divide="ignore"):
        parts = [
            pd.DataFrame(
                {
                    "iteration": sums.index,
                    "metric": metric,
                    "value": (sums[metric] / sums[base].replace(0, np.nan)).to_numpy(),
                }
            )
            for metric, base in (
                ("tool_use", "arm"),
                ("stick_grasp", "arm"),
                ("word_recognised", "voice"),
            )
        ]
    if not words.empty:
        values = words.drop(columns="iteration").replace(np.inf, np.nan)
        for metric, chosen in (
            ("best_distance_names", [w for w in values.columns if w in names]),
            ("best_distance_distractors", [w for w in values.columns if w not in names]),
        ):
            parts.append(
                pd.DataFrame(
                    {
                        "iteration": words["iteration"],
                        "metric": metric,
                        "value": values[chosen].mean(axis=1),
                    }
                )
            )
    return pd.concat(parts, ignore_index=True)


def _read_logs(trial_dir: Path) -> tuple[pd.DataFrame, pd.DataFrame]:
    """(iterations log, words log) of a trial; ReportError if unreadable or missing."""
    try:
        log, words = read_log(trial_dir), read_log(trial_dir, "words")
    except storage.CorruptFileError as exc:
        raise ReportError(str(exc).replace("\n", " ")) from None
    if log.empty:
        raise ReportError(f"{trial_dir.name} has no iteration log (log/iterations-*.parquet)")
    return log, words


def _eval_numbers(trial_dir: Path, summary: dict) -> dict[str, float]:
    """A trial's numbers from its eval.json."""
    try:
        vocal = summary["vocal"]
        return {
            **{f"competence_{k}": summary["competence"][k] for k in COMPETENCE_SCOPES},
            "mean_error": summary["mean_error"],
            "mean_random_error": summary["mean_random_error"],
            "share_below_threshold": vocal["share_below_threshold"],
            "median_names": vocal["median_names"],
            "median_distractors": vocal["median_distractors"],
        }
    except (KeyError, TypeError) as exc:
        raise ReportError(
            f"{trial_dir / EVAL_FILE} lacks {exc}: evaluate the trial again (`playroom eval`)"
        ) from None


def _timing(trial_dir: Path) -> tuple[float, float]:
    path = trial_dir / TIMING_FILE
    if not path.exists():
        return math.nan, math.nan
    timing = _read_json(path)
    try:
        return float(timing["seconds"]), float(timing["iterations"])
    except (KeyError, TypeError, ValueError):
        raise ReportError(f"{path} lacks 'seconds' and 'iterations' numbers") from None


def collect(batch_dir: str | os.PathLike) -> BatchResults:
    """Read every trial of a batch directory into tables. ReportError (one line) for a
    directory without trials, trials not evaluated, or mismatched configs within a group."""
    batch_dir = Path(batch_dir)
    dirs = _trial_dirs(batch_dir)
    configs = [_read_json(d / CONFIG_FILE) for d in dirs]
    evals = [_read_json(d / EVAL_FILE) for d in dirs]
    for d, config in zip(dirs, configs, strict=True):
        if not isinstance(config, dict) or not {"grasp", "babbling", "seed", "iterations"} <= set(
            config.get("trial", {})
        ):
            raise ReportError(f"{d / CONFIG_FILE} lacks the trial's grasp/babbling/seed")
    for d, summary in zip(dirs, evals, strict=True):
        if not isinstance(summary, dict):
            raise ReportError(f"{d / EVAL_FILE} is not an evaluation summary")
    mixed = len({c["trial"]["babbling"] for c in configs}) > 1
    labels = [_group_label(c["trial"]["grasp"], c["trial"]["babbling"], mixed) for c in configs]
    group_configs: dict[str, dict] = {}
    for label in sorted(set(labels)):
        members = [i for i, lab in enumerate(labels) if lab == label]
        _check_group(
            label,
            [dirs[i] for i in members],
            [configs[i] for i in members],
            [evals[i] for i in members],
        )
        group_configs[label] = _shared_config(configs[members[0]])

    trials, competence, vocal, curves = [], [], [], []
    for d, config, summary, label in zip(dirs, configs, evals, labels, strict=True):
        keys = {"trial": d.name, "group": label, "seed": config["trial"]["seed"]}
        comp = _read_table(d / COMPETENCE_FILE).assign(**keys)
        voc = _read_table(d / VOCAL_FILE).assign(**keys)
        log, words = _read_logs(d)
        curve = _curve_rows(
            log, words, config["trial"]["iterations"], set(voc.loc[voc["is_name"], "word"])
        ).assign(**keys)
        seconds, timed = _timing(d)
        trials.append(
            {
                **keys,
                "path": str(d),
                "grasp": config["trial"]["grasp"],
                "babbling": config["trial"]["babbling"],
                "iterations": config["trial"]["iterations"],
                "n_placements": summary.get("n_placements"),
                **_eval_numbers(d, summary),
                "diverged": int(log["diverged"].sum()),
                "seconds": seconds,
                "timed_iterations": timed,
            }
        )
        competence.append(comp)
        vocal.append(voc)
        curves.append(curve)
    return BatchResults(
        batch_dir=batch_dir,
        trials=pd.DataFrame(trials),
        competence=pd.concat(competence, ignore_index=True),
        vocal=pd.concat(vocal, ignore_index=True),
        curves=pd.concat(curves, ignore_index=True),
        configs=group_configs,
    )


# --------------------------------------------------------------------------------------------
# Statistics
# --------------------------------------------------------------------------------------------


def mean_ci(values: np.ndarray, confidence: float = 0.95) -> tuple[float, float, float]:
    """(mean, low, high): Student t interval of the mean; NaN bounds below 2 finite values."""
    values = np.asarray(values, dtype=float)
    values = values[np.isfinite(values)]
    if len(values) == 0:
        return math.nan, math.nan, math.nan
    mean = float(values.mean())
    if len(values) < 2:
        return mean, math.nan, math.nan
    half = stats.t.ppf(0.5 + confidence / 2, len(values) - 1) * stats.sem(values)
    return mean, float(mean - half), float(mean + half)


def competence_summary(trials: pd.DataFrame) -> pd.DataFrame:
    """Per group and scope (all, ring1..3): n trials, mean normalised competence, 95% CI."""
    rows = []
    for group, table in trials.groupby("group", sort=False):
        for scope in COMPETENCE_SCOPES:
            mean, low, high = mean_ci(table[f"competence_{scope}"].to_numpy())
            rows.append(
                {
                    "group": group,
                    "scope": scope,
                    "n": len(table),
                    "mean": mean,
                    "low": low,
                    "high": high,
                }
            )
    return pd.DataFrame(rows, columns=["group", "scope", "n", "mean", "low", "high"])


def regions(hand_limit: float, stick_limit: float) -> dict[str, tuple[float, float]]:
    """The paper's three regions of toy distance for strategy shares (Fig. 4's text)."""
    return {
        "centre": (0.0, hand_limit),
        "between limits": (hand_limit, stick_limit),
        "distance 1": (DISTANCE_ONE, math.inf),
    }


def strategy_counts(
    competence: pd.DataFrame, hand_limit: float, stick_limit: float
) -> pd.DataFrame:
    """Counts of tests per group, region and strategy (hand, tool, vocal columns)."""
    rows = []
    for group, table in competence.groupby("group", sort=False):
        for region, (low, high) in regions(hand_limit, stick_limit).items():
            inside = table[(table["distance"] >= low) & (table["distance"] < high)]
            counts = inside["strategy"].value_counts()
            rows.append(
                {"group": group, "region": region}
                | {s: int(counts.get(s, 0)) for s in figures.STRATEGIES}
            )
    return pd.DataFrame(rows, columns=["group", "region", *figures.STRATEGIES])


def strategy_table(competence: pd.DataFrame, hand_limit: float, stick_limit: float) -> pd.DataFrame:
    """Shares of hand, tool, vocal per group and region, with the number of tests n."""
    counts = strategy_counts(competence, hand_limit, stick_limit)
    n = counts[list(figures.STRATEGIES)].sum(axis=1)
    shares = counts[list(figures.STRATEGIES)].div(n.replace(0, np.nan), axis=0)
    return pd.concat([counts[["group", "region"]], shares, n.rename("n")], axis=1)


def vocal_summary(vocal: pd.DataFrame, threshold: float) -> dict[str, float]:
    """Share of words below the recognition threshold, median best distance of names and
    distractors, and a two-sided Mann-Whitney U test of names against distractors."""
    names = vocal.loc[vocal["is_name"], "best_distance"].to_numpy(dtype=float)
    distractors = vocal.loc[~vocal["is_name"], "best_distance"].to_numpy(dtype=float)
    u, p = mann_whitney(names, distractors)
    return {
        "n_words": len(vocal),
        "share_below": float((vocal["best_distance"] < threshold).mean()),
        "median_names": float(np.median(names)) if len(names) else math.nan,
        "median_distractors": float(np.median(distractors)) if len(distractors) else math.nan,
        "u": u,
        "p": p,
    }


def mann_whitney(a: np.ndarray, b: np.ndarray) -> tuple[float, float]:
    """(U of a, two-sided p); NaN when a side is empty. Infinite values (a word never
    approached) rank above every finite one, which is what they mean."""
    a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    if len(a) == 0 or len(b) == 0:
        return math.nan, math.nan
    result = stats.mannwhitneyu(a, b, alternative="two-sided")
    return float(result.statistic), float(result.pvalue)


def welch(a: np.ndarray, b: np.ndarray) -> tuple[float, float]:
    """(t, two-sided p) of Welch's t test; NaN below 2 values a side or without variance."""
    a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    if len(a) < 2 or len(b) < 2 or (np.var(a) == 0 and np.var(b) == 0):
        return math.nan, math.nan
    result = stats.ttest_ind(a, b, equal_var=False)
    return float(result.statistic), float(result.pvalue)


def chi_square(table: np.ndarray) -> tuple[float, float]:
    """(chi2, p) of a contingency table, leaving out all-zero rows and columns (they carry no
    information and make expected counts zero); NaN when fewer than 2x2 remain."""
    table = np.asarray(table, dtype=float)
    table = table[table.sum(axis=1) > 0][:, table.sum(axis=0) > 0]
    if table.shape[0] < 2 or table.shape[1] < 2:
        return math.nan, math.nan
    result = stats.chi2_contingency(table)
    return float(result.statistic), float(result.pvalue)


def cost_per_iteration(trials: pd.DataFrame) -> float:
    """Seconds of compute per iteration over the trials that recorded timing.json; NaN if
    none did."""
    timed = trials.dropna(subset=["seconds", "timed_iterations"])
    if timed.empty or timed["timed_iterations"].sum() <= 0:
        return math.nan
    return float(timed["seconds"].sum() / timed["timed_iterations"].sum())


def curve_bands(curves: pd.DataFrame) -> pd.DataFrame:
    """Mean over trials and 95% t interval of each curve metric at each iteration."""
    rows = []
    for (group, metric, iteration), table in curves.groupby(
        ["group", "metric", "iteration"], sort=False
    ):
        mean, low, high = mean_ci(table["value"].to_numpy())
        rows.append(
            {
                "group": group,
                "metric": metric,
                "iteration": iteration,
                "mean": mean,
                "low": low,
                "high": high,
            }
        )
    columns = ["group", "metric", "iteration", "mean", "low", "high"]
    return pd.DataFrame(rows, columns=columns).sort_values(["group", "metric", "iteration"])


# --------------------------------------------------------------------------------------------
# Rendering
# --------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class _Geometry:
    """Reach limits and recognition threshold, read from the trials' own settings."""

    hand_limit: float
    stick_limit: float
    threshold: float
    bootstrap: int

    @classmethod
    def of(cls, results: BatchResults) -> _Geometry:
        config = next(iter(results.configs.values()))
        try:
            hand = float(sum(config["world"]["segment_lengths"]))
            stick = hand + float(config["world"]["stick_length"])
            threshold = float(config["voice"]["recognition_distance"])
            learner = config["learner"]
            bootstrap = int(learner["bootstrap_arm"]) + int(learner["bootstrap_voice"])
        except (KeyError, TypeError, ValueError) as exc:
            raise ReportError(
                f"the trials' config.json lacks a setting the report needs ({exc})"
            ) from None
        return cls(hand, stick, threshold, bootstrap)


def _pct(x: float, digits: int = 0) -> str:
    return "n/a" if not np.isfinite(x) else f"{100 * x:.{digits}f}%"


def _num(x: float, digits: int = 2) -> str:
    return "n/a" if not np.isfinite(x) else f"{x:.{digits}f}"


def _p(p: float) -> str:
    if not np.isfinite(p):
        return "n/a"
    return f"p = {p:.3f}" if p >= 1e-3 else f"p = {p:.1e}"


def _ci_text(row: pd.Series) -> str:
    if not np.isfinite(row["mean"]):
        return "n/a"
    if not np.isfinite(row["low"]):
        return f"{_pct(row['mean'], 1)} (n={row['n']}, no interval)"
    interval = f"[95% CI {_pct(row['low'], 1)}, {_pct(row['high'], 1)}]"
    return f"{_pct(row['mean'], 1)} {interval} (n={row['n']})"


def _shares_text(row: pd.Series) -> str:
    if row["n"] == 0:
        return "no tests here"
    shares = " / ".join(_pct(row[s]) for s in figures.STRATEGIES)
    return f"{shares} (n={row['n']} tests)"


def _statistics(results: BatchResults, geometry: _Geometry) -> dict[str, Any]:
    """Every number of the report, per group."""
    summary = competence_summary(results.trials)
    strategies = strategy_table(results.competence, geometry.hand_limit, geometry.stick_limit)
    vocal = {
        g: vocal_summary(results.vocal[results.vocal["group"] == g], geometry.threshold)
        for g in results.groups
    }
    return {"competence": summary, "strategies": strategies, "vocal": vocal}


def _paper_rows(results: BatchResults, numbers: dict, geometry: _Geometry) -> list[list[str]]:
    """[result, paper, value of group 1, value of group 2, ...], one list per row."""
    g = results.groups
    comp, strat, vocal = numbers["competence"], numbers["strategies"], numbers["vocal"]

    def competence_of(scope: str) -> list[str]:
        return [_ci_text(comp[(comp["group"] == x) & (comp["scope"] == scope)].iloc[0]) for x in g]

    def shares_of(region: str) -> list[str]:
        return [
            _shares_text(strat[(strat["group"] == x) & (strat["region"] == region)].iloc[0])
            for x in g
        ]

    h, s, t = geometry.hand_limit, geometry.stick_limit, geometry.threshold
    return [
        [
            "Normalised competence, all rings (mean over trials)",
            "46% better than random on average",
            *competence_of("all"),
        ],
        [
            f"… ring 1 (toy within hand reach, d < {h:g})",
            "not published",
            *competence_of("ring1"),
        ],
        [f"… ring 2 ({h:g} ≤ d < {s:g})", "not published", *competence_of("ring2")],
        [f"… ring 3 ({s:g} ≤ d ≤ 1)", "not published", *competence_of("ring3")],
        [
            f"Strategy hand / tool / vocal, centre region (d < {h:g})",
            "~65% / 15–20% / 15–20%",
            *shares_of("centre"),
        ],
        [
            f"Strategy hand / tool / vocal, between hand and stick limits ({h:g} ≤ d < {s:g})",
            "~50% / 20–30% / 20–30%",
            *shares_of("between limits"),
        ],
        [
            f"Strategy hand / tool / vocal, at distance 1 (d ≥ {DISTANCE_ONE:g})",
            "38% / 13% / 49%",
            *shares_of("distance 1"),
        ],
        [
            f"Words imitated within {t:g} (best distance)",
            "88% (of 2964 words)",
            *[f"{_pct(vocal[x]['share_below'])} (of {vocal[x]['n_words']} words)" for x in g],
        ],
        ["Median best distance, toy names", "0.23", *[_num(vocal[x]["median_names"]) for x in g]],
        [
            "Median best distance, distractors",
            "0.30",
            *[_num(vocal[x]["median_distractors"]) for x in g],
        ],
        [
            "Mann-Whitney U, names vs distractors (two-sided)",
            "p < 1e-72 (1482 vs 1482 words)",
            *[f"U = {_num(vocal[x]['u'], 1)}, {_p(vocal[x]['p'])}" for x in g],
        ],
    ]


def _figures(results: BatchResults, geometry: _Geometry) -> list[tuple[str, str, str, bytes]]:
    """[(file name, title, caption, PNG bytes)] of every figure of a report."""
    g = results.groups
    numbers = competence_summary(results.trials)
    drawn = [
        (
            "fig3-competence-map.png",
            "Competence by toy position (paper Fig. 3)",
            "Normalised competence 1 − Σerror / Σrandom error of the tests whose toy lies in "
            "each cell, pooled over trials: 0% is the random agent on the same placements, 100% "
            "a perfect retrieval. Dashed circles: hand and stick reach limits.",
            figures.competence_map(
                results.competence, g, geometry.hand_limit, geometry.stick_limit
            ),
        ),
        (
            "fig4-strategies.png",
            "Strategy preference by toy distance (paper Fig. 4)",
            "Share of tests in which the agent chose the hand (arm, stick still), the tool "
            "(arm, stick moved) or its voice (caregiver's help), by the toy's distance to the "
            "arm's base. Vertical bars: hand and stick reach limits.",
            figures.strategy_by_distance(
                results.competence, g, geometry.hand_limit, geometry.stick_limit
            ),
        ),
        (
            "fig5-vocal-errors.png",
            "Vocal imitation errors, toy names vs distractors (paper Fig. 5)",
            "Best (lowest) distance between each of the caregiver's words and any sound the "
            f"agent produced; below {geometry.threshold:g} the caregiver recognises the word.",
            figures.vocal_errors(results.vocal, g, geometry.threshold),
        ),
        (
            "development.png",
            "Developmental curves",
            "Per window of iterations, mean over trials with a 95% interval: share of arm "
            "movements that moved a toy with the stick, share of vocal movements the caregiver "
            "recognised as a word, and mean best distance so far to the trial's toy names "
            "(solid) and distractors (dashed). Grey: the random bootstrap.",
            figures.development(
                curve_bands(results.curves), g, geometry.bootstrap, geometry.threshold
            ),
        ),
        (
            "competence-per-trial.png",
            "Competence per trial and ring",
            "Each dot is one trial's normalised competence; diamonds: mean with 95% t interval.",
            figures.competence_by_ring(results.trials, numbers, g, PAPER_COMPETENCE),
        ),
    ]
    return [(name, title, caption, figures.png_bytes(fig)) for name, title, caption, fig in drawn]


def _table(header: list[str], rows: list[list[str]]) -> str:
    """An HTML table of plain-text cells (escaped here, once)."""
    head = "".join(f"<th>{html.escape(h)}</th>" for h in header)
    body = "".join(
        "<tr>" + "".join(f"<td>{html.escape(c)}</td>" for c in row) + "</tr>" for row in rows
    )
    return f"<table><thead><tr>{head}</tr></thead><tbody>{body}</tbody></table>"


def _seeds_text(seeds: list[int]) -> str:
    seeds = sorted(seeds)
    if seeds == list(range(seeds[0], seeds[-1] + 1)) and len(seeds) > 2:
        return f"{seeds[0]}–{seeds[-1]}"
    return ", ".join(map(str, seeds))


def _settings_html(results: BatchResults) -> str:
    rows = []
    for group in results.groups:
        trials = results.trials[results.trials["group"] == group]
        config = results.configs[group]
        rows.append(
            [
                group,
                str(len(trials)),
                _seeds_text(trials["seed"].tolist()),
                str(config["trial"]["iterations"]),
                str(config["trial"]["babbling"]),
                str(trials["n_placements"].iloc[0]),
                str(config.get("package_version", "?")),
            ]
        )
    table = _table(
        [
            "group",
            "trials",
            "seeds",
            "iterations",
            "babbling",
            "placements per ring",
            "package version",
        ],
        rows,
    )
    details = "".join(
        f"<details><summary>Full settings of {html.escape(g)}</summary><pre>"
        f"{html.escape(json.dumps(c, indent=2, sort_keys=True))}</pre></details>"
        for g, c in results.configs.items()
    )
    return table + details


def _trials_html(results: BatchResults) -> str:
    rows = [
        [
            r["trial"],
            r["group"],
            str(r["seed"]),
            *[_pct(r[f"competence_{k}"], 1) for k in COMPETENCE_SCOPES],
            _pct(r["share_below_threshold"]),
            _num(r["median_names"]),
            _num(r["median_distractors"]),
            str(r["diverged"]),
            _num(r["seconds"] / r["timed_iterations"], 4),
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
    return _table(header, rows)


_STYLE = """
body { font-family: sans-serif; max-width: 1250px; margin: 2em auto; color: #222; }
table { border-collapse: collapse; margin: 1em 0; font-size: 0.92em; }
th, td { border: 1px solid #bbb; padding: 0.3em 0.6em; text-align: left; vertical-align: top; }
th { background: #eee; }
img { max-width: 100%; border: 1px solid #ddd; }
figure { margin: 1.5em 0; }
figcaption { font-size: 0.9em; color: #444; max-width: 1000px; }
pre { font-size: 0.8em; background: #f7f7f7; padding: 0.5em; }
"""


def _page(
    title: str, sections: list[tuple[str, str]], pngs: list[tuple[str, str, str, bytes]]
) -> str:
    parts = [f"<h1>{html.escape(title)}</h1>"]
    for heading, body in sections:
        parts.append(f"<h2>{heading}</h2>{body}")
    parts.append("<h2>Figures</h2>")
    for name, fig_title, caption, data in pngs:
        uri = "data:image/png;base64," + base64.b64encode(data).decode("ascii")
        parts.append(
            f'<figure><h3>{html.escape(fig_title)}</h3><img src="{uri}" alt="{html.escape(name)}">'
            f"<figcaption>{html.escape(caption)} (file: {html.escape(name)})</figcaption></figure>"
        )
    return (
        '<!DOCTYPE html>\n<html lang="en"><head><meta charset="utf-8">'
        f"<title>{html.escape(title)}</title><style>{_STYLE}</style></head><body>"
        + "\n".join(parts)
        + "</body></html>\n"
    )


def _write_atomically(path: Path, data: bytes) -> None:
    """A reader sees the old file or the new one, never half of one."""
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".tmp")
    try:
        with os.fdopen(fd, "wb") as f:
            f.write(data)
            f.flush()
            os.fsync(f.fileno())
        # mkstemp makes the file private (0600); a report is meant to be read by others.
        os.chmod(tmp, 0o644)
        os.replace(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise


def _write_all(
    out_dir: Path, pngs: list[tuple[str, str, str, bytes]], page_name: str, page: str
) -> Path:
    """The PNGs, then the page last: a page on disk means its figures are there too."""
    out_dir.mkdir(parents=True, exist_ok=True)
    for name, _, _, data in pngs:
        _write_atomically(out_dir / name, data)
    target = out_dir / page_name
    _write_atomically(target, page.encode("utf-8"))
    return target


def write_report(batch_dir: str | os.PathLike, out_dir: str | os.PathLike | None = None) -> Path:
    """Figures (PNG) and `report.html` of a batch, its numbers beside the paper's; into
    `out_dir` (default: the batch directory). Returns the path of report.html."""
    results = collect(batch_dir)
    geometry = _Geometry.of(results)
    numbers = _statistics(results, geometry)
    pngs = _figures(results, geometry)
    header = [
        "result",
        "paper (500 runs, 80000 iterations)",
        *[f"this batch: {g}" for g in results.groups],
    ]
    paper = _table(header, _paper_rows(results, numbers, geometry)).replace("<tr><td>", "<tr><td>")
    n = len(results.trials)
    sections = [
        (
            "Settings",
            f"<p>{n} trial{'s' if n != 1 else ''} in "
            f"<code>{html.escape(str(results.batch_dir))}</code>.</p>" + _settings_html(results),
        ),
        ("Paper vs this batch", paper + _NOTES),
        ("Trials", _trials_html(results)),
    ]
    page = _page(f"Playroom batch report: {results.batch_dir.name}", sections, pngs)
    return _write_all(
        Path(out_dir) if out_dir is not None else results.batch_dir, pngs, REPORT_FILE, page
    )


_NOTES = (
    "<p>Competence intervals are Student t intervals over trials. Strategy shares are pooled "
    "over every test of the region; hand = arm with the stick still, tool = arm with the stick "
    "moved, vocal = voice. The paper's numbers come from protocol.md (“Evaluation after "
    "learning”).</p>"
)


# --------------------------------------------------------------------------------------------
# Comparison of two batches
# --------------------------------------------------------------------------------------------


def _sides(dir_a: Path, dir_b: Path) -> tuple[BatchResults, BatchResults]:
    """One group per side: two batches of one group each, or one batch of exactly two."""
    a = collect(dir_a)
    if dir_a.resolve() == dir_b.resolve():
        if len(a.groups) != 2:
            raise ReportError(
                f"{dir_a} holds {len(a.groups)} group(s) ({', '.join(a.groups)}): comparing a "
                "batch with itself needs exactly two groups"
            )
        return a.select(a.groups[0]), a.select(a.groups[1])
    b = collect(dir_b)
    for side, path in ((a, dir_a), (b, dir_b)):
        if len(side.groups) != 1:
            raise ReportError(
                f"{path} holds {len(side.groups)} groups ({', '.join(side.groups)}): a "
                "comparison takes one group per batch"
            )
    if a.groups == b.groups:  # two batches of the same backend: tell them apart by folder
        a = a.relabel({a.groups[0]: f"{a.groups[0]} ({dir_a.name})"})
        b = b.relabel({b.groups[0]: f"{b.groups[0]} ({dir_b.name})"})
    return a, b


def _merge(a: BatchResults, b: BatchResults) -> BatchResults:
    tables = {
        name: pd.concat([getattr(a, name), getattr(b, name)], ignore_index=True)
        for name in ("trials", "competence", "vocal", "curves")
    }
    return BatchResults(batch_dir=a.batch_dir, **tables, configs={**a.configs, **b.configs})


def _per_second(cost: float) -> str:
    return "not recorded" if not np.isfinite(cost) else f"{1000 * cost:.2f} ms / iteration"


def _difference_rows(a: BatchResults, b: BatchResults, geometry: _Geometry) -> list[list[str]]:
    """[statistic, A, B, test, p] rows: is the difference between the two groups real?"""
    rows = []
    summary = competence_summary(pd.concat([a.trials, b.trials]))
    for scope in COMPETENCE_SCOPES:
        values = [side.trials[f"competence_{scope}"].to_numpy() for side in (a, b)]
        texts = [
            _ci_text(
                summary[(summary["group"] == s.groups[0]) & (summary["scope"] == scope)].iloc[0]
            )
            for s in (a, b)
        ]
        name = "all rings" if scope == "all" else scope.replace("ring", "ring ")
        rows.append(
            [
                f"Normalised competence, {name}",
                *texts,
                "Welch t (per-trial values)",
                _p(welch(*values)[1]),
            ]
        )
    counts = strategy_counts(
        pd.concat([a.competence, b.competence]), geometry.hand_limit, geometry.stick_limit
    )
    shares = strategy_table(
        pd.concat([a.competence, b.competence]), geometry.hand_limit, geometry.stick_limit
    )
    for region in regions(geometry.hand_limit, geometry.stick_limit):
        table = counts[counts["region"] == region]
        texts = [
            _shares_text(
                shares[(shares["group"] == s.groups[0]) & (shares["region"] == region)].iloc[0]
            )
            for s in (a, b)
        ]
        matrix = table.set_index("group").loc[[a.groups[0], b.groups[0]], list(figures.STRATEGIES)]
        rows.append(
            [
                f"Strategy hand / tool / vocal, {region}",
                *texts,
                "χ² (pooled tests, groups × strategies)",
                _p(chi_square(matrix.to_numpy())[1]),
            ]
        )
    t = geometry.threshold
    below = [(s.vocal["best_distance"] < t).sum() for s in (a, b)]
    total = [len(s.vocal) for s in (a, b)]
    fisher = stats.fisher_exact([[below[0], total[0] - below[0]], [below[1], total[1] - below[1]]])
    rows.append(
        [
            f"Words imitated within {t:g}",
            *[
                f"{_pct(n / m if m else math.nan)} of {m}"
                for n, m in zip(below, total, strict=True)
            ],
            "Fisher exact (pooled words)",
            _p(float(fisher.pvalue)),
        ]
    )
    for label, pick in (
        ("all words", lambda v: v),
        ("toy names", lambda v: v[v["is_name"]]),
        ("distractors", lambda v: v[~v["is_name"]]),
    ):
        values = [pick(s.vocal)["best_distance"].to_numpy(dtype=float) for s in (a, b)]
        rows.append(
            [
                f"Best word distance, {label} (median)",
                *[f"{_num(np.median(v)) if len(v) else 'n/a'} (n={len(v)})" for v in values],
                "Mann-Whitney U (pooled words)",
                _p(mann_whitney(*values)[1]),
            ]
        )
    diverged = [int(s.trials["diverged"].sum()) for s in (a, b)]
    iterations = [int(s.trials["iterations"].sum()) for s in (a, b)]
    rows.append(
        [
            "Iterations whose physics diverged",
            *[f"{d} of {n}" for d, n in zip(diverged, iterations, strict=True)],
            "χ² (pooled iterations)",
            _p(
                chi_square(
                    np.array([[d, n - d] for d, n in zip(diverged, iterations, strict=True)])
                )[1]
            ),
        ]
    )
    costs = [cost_per_iteration(s.trials) for s in (a, b)]
    ratio = costs[1] / costs[0] if all(np.isfinite(costs)) and costs[0] > 0 else math.nan
    rows.append(
        [
            "Cost per iteration (timing.json: trial seconds / iterations)",
            *[_per_second(c) for c in costs],
            f"ratio {b.groups[0]} / {a.groups[0]}",
            "n/a" if not np.isfinite(ratio) else f"{ratio:.2f}×",
        ]
    )
    return rows


def write_comparison(
    dir_a: str | os.PathLike, dir_b: str | os.PathLike, out_dir: str | os.PathLike
) -> Path:
    """Two batches (e.g. kinematic and physical grasping) side by side: every figure with one
    panel per batch, the paper table with both, tests of their differences and the cost per
    iteration of each. `dir_a` may equal `dir_b` for one batch of exactly two groups. Writes
    `comparison.html` and `comparison-*.png` into out_dir; returns the page's path."""
    dir_a, dir_b = Path(dir_a), Path(dir_b)
    a, b = _sides(dir_a, dir_b)
    merged = _merge(a, b)
    geometry = _Geometry.of(merged)
    numbers = _statistics(merged, geometry)
    pngs = [
        (f"comparison-{name}", title, caption, data)
        for name, title, caption, data in _figures(merged, geometry)
    ]
    g = merged.groups
    paper = _table(
        ["result", "paper (500 runs, 80000 iterations)", *g],
        _paper_rows(merged, numbers, geometry),
    )
    tests = _table(
        ["statistic", g[0], g[1], "test of the difference", "p"],
        _difference_rows(a, b, geometry),
    )
    where = " and ".join(
        f"<code>{html.escape(str(p))}</code>" for p in dict.fromkeys((dir_a, dir_b))
    )
    sections = [
        (
            "Settings",
            f"<p>{len(a.trials)} + {len(b.trials)} trials from {where}.</p>"
            + _settings_html(merged),
        ),
        ("Differences between the two", tests + _TEST_NOTES),
        ("Paper vs the two", paper + _NOTES),
        ("Trials", _trials_html(merged)),
    ]
    page = _page(f"Playroom comparison: {g[0]} vs {g[1]}", sections, pngs)
    return _write_all(Path(out_dir), pngs, COMPARISON_FILE, page)


_TEST_NOTES = (
    "<p>All tests are two-sided. Competence: Welch's t test on the per-trial values (needs two "
    "trials a side). Strategies: χ² test of independence on the pooled counts of tests in the "
    "region (tests of one trial are not independent, so read it as indicative). Word "
    "distances: Mann-Whitney U on the best distances of every word of every trial. Cost: "
    "wall-clock seconds per iteration that the trials recorded in timing.json.</p>"
)
