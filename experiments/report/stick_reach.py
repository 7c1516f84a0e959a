"""Where the learning arm still grasps the stick: the grasp rate of arm movements against the
handle's distance from the arm's base when they began, per grasp backend, from a batch's logs
(`experiments.analysis.curves.grasp_rate_by_distance`). The measurement behind the return
reach docs/protocol.md D14 proposes; docs/stick-grasp-rate.png was drawn by

    python -m experiments.report.stick_reach BATCH_DIR --out docs/stick-grasp-rate.png

which also prints the table (markdown) and, per backend, the distance `falling_rate_distance`
finds where it finds one. Each backend's reach is drawn as its trials recorded it
(experiments/trial_dir/backend_record.py): any set of backends, none known here by name.
"""

from __future__ import annotations

import argparse
import math
import os
import platform
import sys
import textwrap
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd
from matplotlib.figure import Figure

from experiments.analysis.curves import falling_rate_distance, grasp_rate_by_distance
from experiments.analysis.logs import read_log
from experiments.report.figures import group_colour, png_bytes
from experiments.trial_dir import provenance, storage
from experiments.trial_dir.reading import open_for_reading

# The proposal's rule (falling_rate_distance): the first 1 cm bin beyond the start pose's whose
# grasp rate is below half of the start's, among bins of at least 100 arm movements.
BIN_WIDTH = 0.01
FRACTION = 0.5
MIN_ITERATIONS = 100


@dataclass(frozen=True)
class BatchRates:
    """Per backend of a batch: the rate table of its trials' logs pooled, its trials' config
    and backend record (backend.json), and how many trials it has."""

    rates: dict[str, pd.DataFrame]
    configs: dict[str, dict]
    records: dict[str, dict]
    counts: dict[str, int]


def batch_rates(batch_dir: Path, bin_width: float = BIN_WIDTH) -> BatchRates:
    """The batch's trials by backend (`BatchRates`)."""
    logs: dict[str, list[pd.DataFrame]] = {}
    configs: dict[str, dict] = {}
    records: dict[str, dict] = {}
    # Every folder with a config.json, in order.
    for trial in (t for t in map(open_for_reading, sorted(batch_dir.iterdir())) if t.has_config()):
        config = trial.config_json()
        grasp = config["trial"]["grasp"]
        logs.setdefault(grasp, []).append(read_log(trial.dir))
        configs[grasp] = config
        records[grasp] = trial.backend(config)
    rates = {g: grasp_rate_by_distance(pd.concat(ls), bin_width) for g, ls in logs.items()}
    return BatchRates(rates, configs, records, {g: len(ls) for g, ls in logs.items()})


def start_distance(config: dict) -> float:
    return float(np.hypot(*config["world"]["stick_start_handle"]))


def distance_lines(batch: BatchRates) -> list[tuple[float, str, str, str]]:
    """(distance, colour, line style, label) of the figure's vertical lines: the stick's start,
    then per backend, in its colour, its reach as its trials recorded it (dashed) and the return
    reach its grasp rate proposes (solid), where the rule finds one."""
    config = next(iter(batch.configs.values()))
    lines = [(start_distance(config), "k", ":", "stick's start")]
    groups = sorted(batch.rates)
    for grasp in groups:
        colour, reach = group_colour(groups, grasp), float(batch.records[grasp]["reach"])
        lines.append((reach, colour, "--", f"{grasp}: the hand's reach ({reach:.3g} m)"))
        proposed = proposal(batch.rates[grasp], batch.configs[grasp])
        if math.isfinite(proposed):
            lines.append((proposed, colour, "-", f"{grasp}: proposed return reach"))
    return lines


def figure(batch: BatchRates, caption: str) -> Figure:
    """Grasp rate per bin (top) and arm movements per bin (bottom), one line per backend, with
    the start distance, each backend's reach and the return reach proposed for it."""
    fig = Figure(figsize=(9.0, 6.4), layout="constrained")
    top, bottom = fig.subplots(2, 1, sharex=True, height_ratios=(2, 1))
    rates = batch.rates
    groups = sorted(rates)
    for grasp in groups:
        table, colour = rates[grasp], group_colour(groups, grasp)
        centre = (table["low"] + table["high"]) / 2
        top.plot(centre, 100 * table["rate"], "o-", ms=3, color=colour, label=grasp)
        bottom.bar(
            table["low"],
            table["iterations"],
            width=BIN_WIDTH,
            align="edge",
            color=colour,
            alpha=0.5,
            label=grasp,
        )
    for x, colour, style, label in distance_lines(batch):
        for ax in (top, bottom):
            ax.axvline(x, color=colour, ls=style, lw=1, label=label if ax is top else None)
    top.set_ylabel("arm movements that grasp the stick (%)")
    top.legend(fontsize=8)
    top.set_title("Grasp rate against the handle's distance from the arm's base")
    bottom.set_ylabel("arm movements")
    bottom.set_yscale("log")
    bottom.set_xlabel(
        f"handle's distance from the base when the movement began (m, {BIN_WIDTH:g} m bins)"
    )
    # A figure label, so that the constrained layout keeps room for it below the axes.
    fig.supxlabel(textwrap.fill(caption, 150), fontsize=7, x=0.01, ha="left")
    return fig


def proposal(rates: pd.DataFrame, config: dict) -> float:
    """The return reach D14's rule proposes from a backend's rate table (NaN: none)."""
    return falling_rate_distance(rates, start_distance(config), FRACTION, MIN_ITERATIONS)


def markdown(rates: dict[str, pd.DataFrame]) -> str:
    """One row per bin: distance, then iterations and grasp rate of each backend."""
    groups = sorted(rates)
    merged = None
    for g in groups:
        part = rates[g].set_index("low")[["iterations", "rate"]].add_prefix(f"{g} ")
        merged = part if merged is None else merged.join(part, how="outer")
    assert merged is not None
    header = (
        "| handle distance (m) | "
        + " | ".join(f"{g} arm movements | {g} grasp rate" for g in groups)
        + " |"
    )
    rows = [header, "|" + "---|" * (1 + 2 * len(groups))]
    for index, row in merged.sort_index().iterrows():
        low = float(index)  # type: ignore[arg-type]  # the bins' low edges, floats
        cells = []
        for g in groups:
            n, r = row[f"{g} iterations"], row[f"{g} rate"]
            cells += ["", ""] if pd.isna(n) else [str(int(n)), f"{100 * r:.1f}%"]
        rows.append(f"| {low:.2f}-{low + BIN_WIDTH:.2f} | " + " | ".join(cells) + " |")
    return "\n".join(rows)


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m experiments.report.stick_reach")
    parser.add_argument("batch_dir", type=Path)
    parser.add_argument("--out", type=Path, required=True, help="the figure (PNG)")
    args = parser.parse_args(argv)
    batch = batch_rates(args.batch_dir)
    rates = batch.rates
    if not rates:
        print(f"{args.batch_dir} holds no trial", file=sys.stderr)
        return 2
    machine = provenance.short_record(provenance.machine_record())
    assert machine is not None  # a record was given
    command = f"python -m experiments.report.stick_reach {args.batch_dir} --out {args.out}"
    trials = ", ".join(f"{g}: {batch.counts[g]} trials" for g in sorted(rates))
    caption = (
        f"{command}: logs of {args.batch_dir} ({trials}); drawn on {machine['cpu']} "
        f"({os.cpu_count()} cores, {platform.machine()}, NumPy SIMD {machine['simd']}), "
        f"commit {machine['commit']}. "
        f"Proposed: the first bin past the start's whose rate is below {FRACTION:g} x the "
        f"start bin's, bins of >= {MIN_ITERATIONS} movements."
    )
    storage.write_files(args.out.parent, {args.out.name: png_bytes(figure(batch, caption))})
    print(markdown(rates))
    for grasp in sorted(rates):
        proposed = proposal(rates[grasp], batch.configs[grasp])
        if math.isfinite(proposed):
            print(f"proposed {grasp} return reach: {proposed:.2f} m")
    return 0


if __name__ == "__main__":
    sys.exit(main())
