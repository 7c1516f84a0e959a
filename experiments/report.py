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


def _curve_rows(trial_dir: Path, iterations: int, names: set[str]) -> pd.DataFrame:
    """A trial's developmental curves, in windows of iterations."""
    log = read_log(trial_dir)
    if log.empty:
        raise ReportError(f"{trial_dir.name} has no iteration log (log/iterations-*.parquet)")
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
    words = read_log(trial_dir, "words")
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
        curve = _curve_rows(
            d, config["trial"]["iterations"], set(voc.loc[voc["is_name"], "word"])
        ).assign(**keys)
        seconds, timed = _timing(d)
        log = read_log(d)
        trials.append(
            {
                **keys,
                "path": str(d),
                "grasp": config["trial"]["grasp"],
                "babbling": config["trial"]["babbling"],
                "iterations": config["trial"]["iterations"],
                "n_placements": summary.get("n_placements"),
                **{f"competence_{k}": summary["competence"][k] for k in COMPETENCE_SCOPES},
                "mean_error": summary["mean_error"],
                "mean_random_error": summary["mean_random_error"],
                "share_below_threshold": summary["vocal"]["share_below_threshold"],
                "median_names": summary["vocal"]["median_names"],
                "median_distractors": summary["vocal"]["median_distractors"],
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
                {"group": group, "scope": scope, "n": len(table), "mean": mean, "low": low,
                 "high": high}
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
            {"group": group, "metric": metric, "iteration": iteration, "mean": mean, "low": low,
             "high": high}
        )
    columns = ["group", "metric", "iteration", "mean", "low", "high"]
    return pd.DataFrame(rows, columns=columns).sort_values(["group", "metric", "iteration"])
