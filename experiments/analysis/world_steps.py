"""Steps between conditions (two rungs of the contact ladder, or a condition and its ablation),
each split by the world that tests the agents, with tests over trials paired by seed: the split
and the tests are experiments/analysis/step_split.py's, the ones the ladder's page uses.

For conditions A and B (batch directories of the same seeds), from their own evaluations and
their evaluations in other eval worlds (`playroom eval DIR --world`, eval_worlds.py): the whole
step (each in its own world), and for each test world both were tested in, both tested there
(B in it - A in it) and each one's own world against it ((B own - B in it) - (A own - A in
it)); the two parts add up to the whole. Each difference: the mean over seeds of B minus A,
its Student t 95% interval, the paired t test's two-sided p and the Wilcoxon signed-rank p.
The family is every test printed (each step given on the command line x its parts x the
competence measures); Holm's correction over it, for each kind of p, marks with * those that
survive, and the rows whose star differs between the two are listed after the table.

    python -m experiments.analysis.world_steps NAME=BATCH_DIR NAME=BATCH_DIR ... --steps A:B ...
"""

from __future__ import annotations

import argparse
import math
from pathlib import Path

import pandas as pd

from experiments.analysis import step_split
from experiments.analysis.cross_worlds import RINGS, STRATEGIES, checked_summary, tested_in
from experiments.analysis.logs import trial_dirs
from experiments.analysis.trial_tests import ALPHA, survives
from experiments.trial_dir.reading import open_for_reading

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
    Each evaluation's eval.json is checked (experiments/trial_dir/eval_record.py), and its tables
    against it unless not `check` (copies of eval.json without their tables, said on the command
    line)."""
    rows = []
    for condition, batch_dir in conditions.items():
        for trial in trial_dirs(batch_dir):
            config = open_for_reading(trial).config()
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


def _series(table: pd.DataFrame, condition: str, tested: str, measure: str) -> pd.Series:
    rows = table[(table["condition"] == condition) & (table["tested"] == tested)]
    return rows.set_index("seed")[measure]


def step_rows(table: pd.DataFrame, a: str, b: str, measures=MEASURES) -> list[dict]:
    """The whole step from A to B and, in each test world both were tested in, its two parts
    (step_split.split_step), per measure."""
    held = set(map(tuple, table[["condition", "tested"]].drop_duplicates().to_numpy()))
    worlds = [w for w in WORLDS if (a, w) in held and (b, w) in held]
    rows = []
    for m in measures:
        a_own, b_own = _series(table, a, OWN, m), _series(table, b, OWN, m)
        parts = [(step_split.PART_TEXT[step_split.WHOLE], step_split.paired_test(b_own, a_own))]
        for world in worlds:
            a_in, b_in = _series(table, a, world, m), _series(table, b, world, m)
            split = step_split.split_step(a_own, b_own, a_in, b_in)
            parts += [(step_split.PART_TEXT[k].format(world=world), t) for k, t in split.items()]
        rows += [{"step": f"{a} -> {b}", "part": p, "measure": m, **t} for p, t in parts]
    return rows


def _p_text(p: float, adjusted: float) -> str:
    mark = " *" if survives(adjusted) else ""
    return "n/a" if math.isnan(p) else f"{p:.2g}{mark}"


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
    (rows,) = step_split.with_holm(rows)
    if args.csv:
        rows.to_csv(args.csv, index=False)
    n = step_split.counts([rows])
    print(
        f"{n['family']} tests, paired by seed ({n['made']} made: every difference equal is no "
        f"test); * survives Holm's correction over all of them at {ALPHA} ({n['t']} with the "
        f"paired t, {n['rank']} with the signed-rank test)"
    )
    print("| step | part | measure | B - A (points) | 95% interval | t p | signed-rank p | n |")
    print("|---|---|---|---|---|---|---|---|")
    records = rows.to_dict("records")
    for r in records:
        low, high = 100 * float(r["low"]), 100 * float(r["high"])
        print(
            f"| {r['step']} | {r['part']} | {str(r['measure']).removeprefix('competence_')} | "
            f"{100 * float(r['mean']):+.1f} | [{low:+.1f}, {high:+.1f}] | "
            f"{_p_text(float(r['p']), float(r['p_holm']))} | "
            f"{_p_text(float(r['p_rank']), float(r['p_rank_holm']))} | {r['n']} |"
        )
    differ = [r for r in records if step_split.stars_differ(r)]
    print(f"Stars that differ between the t and the signed-rank test: {len(differ)}")
    for r in differ:
        print(f"- {r['step']}, {r['part']}, {r['measure']}")


if __name__ == "__main__":
    main()
