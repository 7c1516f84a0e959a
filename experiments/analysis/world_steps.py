"""One step between two conditions (two rungs of the contact ladder, or a condition and its
ablation), split into what the agents learned and what the test world does, with a test over
trials paired by seed.

For conditions A and B (batch directories of the same seeds), from their own evaluations and
their evaluations in other eval worlds (`playroom eval DIR --world`, eval_worlds.py):
- the whole step: B's agents in B's own world against A's in A's own (what the comparison
  reports);
- what the agents learned: B's agents against A's, both tested in the same world (each test
  world both were tested in; a condition's own world counts as the world it equals);
- what the test world does: B's agents in B's own world against B's agents in A's world.
Each difference is the mean over seeds of B minus A, with its Student t 95% interval and the
paired t test's two-sided p (scipy.stats.ttest_rel): the unit is the agent. Holm's correction
over every test printed marks those that survive.

    python -m experiments.analysis.world_steps NAME=BATCH_DIR NAME=BATCH_DIR ... --steps A:B ...
"""

from __future__ import annotations

import argparse
import math
from pathlib import Path

import numpy as np
import pandas as pd
from scipy import stats

from experiments import storage
from experiments.analysis import trial_tests
from experiments.analysis.cross_worlds import RINGS, STRATEGIES, checked_summary, tested_in
from experiments.analysis.logs import trial_dirs
from experiments.config_file import with_added_settings
from experiments.file_names import CONFIG_FILE

OWN = "own"
MEASURES = ("competence_all", "competence_ring1", "competence_ring2", "competence_ring3")
WORLDS = ("kinematic", "physical")


def _numbers(summary: dict) -> dict[str, float]:
    row = {f"competence_{k}": float(v) for k, v in summary["competence"].items()}
    for ring in RINGS:
        shares = summary["strategy_share"].get(ring, {})
        row.update({f"{s}_{ring}": float(shares.get(s, 0.0)) for s in STRATEGIES})
    return row


def evaluations(conditions: dict[str, Path], check: bool = True) -> pd.DataFrame:
    """One row per (condition, seed, tested): `tested` is "own" (the trial's own evaluation) or
    a test world it was tested in (its cross-evaluation, or its own where it learned there).
    Each evaluation's eval.json is checked (experiments/eval_record.py), and its tables against
    it unless not `check` (copies of eval.json without their tables, said on the command
    line)."""
    rows = []
    for condition, batch_dir in conditions.items():
        for trial in trial_dirs(batch_dir):
            config = with_added_settings(storage.read_json(trial / CONFIG_FILE))
            summary = checked_summary(trial, trial, config, check)
            keys = {"condition": condition, "seed": int(summary["seed"])}
            rows.append({**keys, "tested": OWN, **_numbers(summary)})
            for world in WORLDS:
                try:
                    tested, _ = tested_in(trial, world, check)
                except ValueError:  # not tested there
                    continue
                rows.append({**keys, "tested": world, **_numbers(tested)})
    return pd.DataFrame(rows)


def paired(
    table: pd.DataFrame, a: tuple[str, str], b: tuple[str, str], measure: str
) -> dict[str, float]:
    """B minus A over the seeds both hold ((condition, tested) each): mean, 95% interval, the
    paired t test's p, n."""

    def values(key: tuple[str, str]) -> pd.Series:
        rows = table[(table["condition"] == key[0]) & (table["tested"] == key[1])]
        return rows.set_index("seed")[measure]

    both = pd.concat([values(a), values(b)], axis=1, keys=["a", "b"]).dropna()
    diff = (both["b"] - both["a"]).to_numpy()
    n = len(diff)
    if n < 2:
        return {"mean": math.nan, "low": math.nan, "high": math.nan, "p": math.nan, "n": n}
    half = stats.t.ppf(0.975, n - 1) * diff.std(ddof=1) / math.sqrt(n)
    p = float(stats.ttest_rel(both["b"], both["a"]).pvalue) if np.any(diff) else 1.0
    mean = float(diff.mean())
    return {"mean": mean, "low": mean - half, "high": mean + half, "p": p, "n": n}


def step_rows(table: pd.DataFrame, a: str, b: str, measures=MEASURES) -> list[dict]:
    """The whole step from A to B, what the agents learned (in each world both were tested
    in) and what the test world does (B in its own world against B in A's), per measure."""
    held = set(map(tuple, table[["condition", "tested"]].drop_duplicates().to_numpy()))
    parts = [("whole step (own worlds)", (a, OWN), (b, OWN))]
    for world in WORLDS:
        a_in = (a, world) if (a, world) in held else None
        b_in = (b, world) if (b, world) in held else None
        if a_in and b_in:
            parts.append((f"learned (both tested in the {world} world)", a_in, b_in))
    a_world = _own_world(table, a)
    if a_world is not None and (b, a_world) in held:
        parts.append((f"test world ({b} in its own against in {a_world})", (b, a_world), (b, OWN)))
    return [
        {"step": f"{a} -> {b}", "part": part, "measure": m, **paired(table, x, y, m)}
        for part, x, y in parts
        for m in measures
    ]


def _own_world(table: pd.DataFrame, condition: str) -> str | None:
    """The test world a condition's own world equals (its own rows equal that world's), if any."""
    mine = table[table["condition"] == condition]
    own = mine[mine["tested"] == OWN].set_index("seed")[list(MEASURES)]
    for world in WORLDS:
        there = mine[mine["tested"] == world].set_index("seed")[list(MEASURES)]
        if len(there) and there.equals(own.loc[there.index]):
            return world
    return None


def holm(p: pd.Series) -> pd.Series:
    """Holm's step-down adjusted p-values (NaN left out): trial_tests.holm, by index."""
    return pd.Series(trial_tests.holm(p.astype(float).tolist()), index=p.index)


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("batches", nargs="+", metavar="NAME=DIR")
    parser.add_argument("--steps", nargs="+", required=True, metavar="A:B")
    parser.add_argument("--csv", help="write every test here too")
    parser.add_argument(
        "--eval-json-only",
        action="store_true",
        help="read each evaluation's eval.json without checking its tables (evaluations copied "
        "from another machine without them); said in the output's first line",
    )
    args = parser.parse_args(argv)
    conditions = {k: Path(v) for k, v in (b.split("=", 1) for b in args.batches)}
    table = evaluations(conditions, check=not args.eval_json_only)
    if args.eval_json_only:
        print("eval.json read without checking the tables it lists (--eval-json-only)")
    rows = pd.DataFrame([r for s in args.steps for r in step_rows(table, *s.split(":", 1))])
    rows["p_holm"] = holm(rows["p"])
    if args.csv:
        rows.to_csv(args.csv, index=False)
    print(f"{len(rows)} tests, paired by seed; * survives Holm's correction at 0.05")
    print("| step | part | measure | B - A (points) | 95% interval | p | n |")
    print("|---|---|---|---|---|---|---|")
    for r in rows.to_dict("records"):
        mark = " *" if float(r["p_holm"]) < 0.05 else ""
        p = "n/a" if math.isnan(float(r["p"])) else f"{float(r['p']):.2g}{mark}"
        low, high = 100 * float(r["low"]), 100 * float(r["high"])
        print(
            f"| {r['step']} | {r['part']} | {str(r['measure']).removeprefix('competence_')} | "
            f"{100 * float(r['mean']):+.1f} | [{low:+.1f}, {high:+.1f}] | {p} | {r['n']} |"
        )


if __name__ == "__main__":
    main()
