"""The study's strategies by the name of the tested toy.

The vocal strategy brings a toy only when the caregiver recognises its name, so a toy's share
of vocal tests should follow how well the agent learned to say that name. This module joins a
batch's study tests (one row per test: trial, toy, ring, strategy;
experiments/measure/study_measure.py) with each trial's vocal table (the word naming each toy
and the agent's best distance to it) and gives the hand, tool and vocal shares of the tests:
- per word: of the toys that word names, over the trials where it names one;
- per "said": of the toys whose name the agent said within the recognition distance at least
  once, and of the others.
The tests keep the study's rings (toy distance from the arm's base, `WorldConfig.toy_rings`).
"""

from __future__ import annotations

import pandas as pd

from experiments.analysis.results import BatchResults
from experiments.analysis.stats import STRATEGIES
from experiments.report.pages import Table, pct

NOT_RECORDED = (
    "Not shown: some trials were evaluated before the vocal table recorded which toy each "
    "name names; run `playroom eval` on them again (the other results do not change)."
)


def named_tests(results: BatchResults, threshold: float) -> pd.DataFrame | None:
    """The study tests with `word` (the tested toy's name), `best_distance` (the agent's best
    to it) and `said` (best_distance below `threshold`). None when the batch has no study tests
    or a trial's vocal table lacks the `toy` column."""
    vocal, tests = results.vocal, results.study_tests
    if tests.empty or "toy" not in vocal or vocal["toy"].isna().any():
        return None
    names = vocal.loc[vocal["toy"] > 0, ["trial", "group", "toy", "word", "best_distance"]]
    names = names.astype({"toy": int})
    named = tests.merge(names, on=["trial", "group", "toy"], how="inner", validate="many_to_one")
    return named.assign(said=named["best_distance"] < threshold)


def strategy_shares(named: pd.DataFrame, keys: list[str]) -> pd.DataFrame:
    """Per `keys` and ring: `tests`, `toys` (distinct trial-toy pairs) and the share of each
    strategy."""
    rows = []
    for key, table in named.groupby([*keys, "ring"], sort=True):
        counts = table["strategy"].value_counts()
        rows.append(
            dict(zip([*keys, "ring"], key, strict=True))
            | {"tests": len(table), "toys": len(table[["trial", "toy"]].drop_duplicates())}
            | {s: counts.get(s, 0) / len(table) for s in STRATEGIES}
        )
    return pd.DataFrame(rows)


def name_strategy_table(results: BatchResults, threshold: float) -> Table | None:
    """The report's table: per group, a row per word (sorted by how often the agent said it
    within the threshold) and a row for names said / never said; the vocal share per ring and
    the three shares in the outermost ring. None when `named_tests` is None."""
    named = named_tests(results, threshold)
    if named is None:
        return None
    # Every ring of the study's tests (`toy_rings`), so each group's row has the same columns.
    n_rings = len(next(iter(results.configs.values()))["world"]["toy_rings"])
    rings = list(range(1, n_rings + 1))
    outer = rings[-1]
    header = [
        "group",
        "toy's name",
        "toys named (trials)",
        f"said within {threshold:g}",
        *[f"vocal, ring {r}" for r in rings],
        f"hand / tool / vocal, ring {outer}",
    ]
    by_word = strategy_shares(named, ["group", "word"])
    by_said = strategy_shares(named, ["group", "said"])
    said_share = named.drop_duplicates(["trial", "toy"]).groupby(["group", "word"])["said"].mean()
    rows = []
    for group in results.groups:
        if group not in said_share.index.get_level_values("group"):
            continue  # a group without study tests
        for word, share in said_share.loc[group].sort_values(ascending=False).items():
            shares = by_word[(by_word["group"] == group) & (by_word["word"] == word)]
            rows.append([group, word, *_cells(shares, rings, outer, pct(share))])
        for said, label in ((True, "names said within the distance"), (False, "names never said")):
            shares = by_said[(by_said["group"] == group) & (by_said["said"] == said)]
            if not shares.empty:
                rows.append([group, label, *_cells(shares, rings, outer, "")])
    return Table(header, rows)


def page_context(results: BatchResults, threshold: float) -> dict:
    """What the pages' "Strategies by the toy's name" section reads (macros.html.j2)."""
    table = name_strategy_table(results, threshold)
    return {
        "has_study_tests": not results.study_tests.empty,
        "name_strategies": table,
        "name_strategies_note": NOT_RECORDED if table is None else "",
    }


def _cells(shares: pd.DataFrame, rings: list[int], outer: int, said: str) -> list[str]:
    """A row's cells after its label: toys, said share, vocal per ring, the outer ring's
    shares."""
    by_ring = shares.set_index("ring")
    vocal = [pct(by_ring["vocal"].loc[r]) if r in by_ring.index else "n/a" for r in rings]
    if outer in by_ring.index:
        last = " / ".join(pct(by_ring[s].loc[outer]) for s in STRATEGIES)
    else:
        last = "n/a"
    return [str(int(by_ring["toys"].max())), said, *vocal, last]
