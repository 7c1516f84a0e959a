"""The reference trials that tests/run/test_reference_logs.py compares against, and how they are
recorded again.

A reference trial is 2000 iterations of seed 11 under the project preset with the stick return
off (the settings the first logs were recorded with, 2026-11-22). What of it can be compared
across machines, measured on 5 BLAS/SIMD variants of a 2-core AMD EPYC without AVX-512 and
against logs recorded on one with AVX-512:
- the kinematic trial's logs are the same on every CPU: its events are thresholds on distances,
  flipped only by a distance within rounding error of a threshold, which none came near;
- in the physical trial, the learner's choices (motor space and model of every iteration) are
  the same on every CPU: under random babbling they come from the agent's PCG64 stream alone;
  its events are not: contacts amplify the last bits of NumPy's and OpenBLAS's kernels (the
  trial of another OpenBLAS kernel differed in 48 rows from iteration 1901 on). Its event
  counts are compared within the spread of other seeds, and its logs bit for bit only on a
  machine whose record (experiments/trial_dir/provenance.py) is the recording's.

Run from the checkout, after a change meant to alter behaviour (say so in the commit):
    .venv/bin/python tests/reference_trials.py logs     # the two trials' logs, and this machine
                                                        # (--grasp physical: that one only)
    .venv/bin/python tests/reference_trials.py spread   # the physical counts of seeds 12-19
"""

from __future__ import annotations

import argparse
import json
import sys
import tempfile
from pathlib import Path

import pandas as pd

DATA = Path(__file__).parent / "data"
SEED, ITERATIONS = 11, 2000
SPREAD_SEEDS = tuple(range(12, 20))
GRASPS = ("kinematic", "physical")
# The learner's choices: the same on every CPU under random babbling (module docstring).
CHOICE_COLUMNS = ["iteration", "motor_space", "model"]
SPREAD_FILE = DATA / "reference-physical-spread.json"


def settings(grasp: str, seed: int = SEED):
    from experiments.run.settings import TrialSettings

    return TrialSettings(
        grasp=grasp,
        iterations=ITERATIONS,
        seed=seed,
        checkpoint_every=1000,
        stick_return="never",  # added later; off, as when the logs were first recorded
        preset="project",  # the choices the logs were first recorded with
    )


def log_path(grasp: str, kind: str) -> Path:
    return DATA / f"reference-{grasp}-seed{SEED}-{ITERATIONS}-{kind}.parquet"


def machine_path(grasp: str) -> Path:
    """Where the record of the machine that recorded a trial's logs is kept."""
    return DATA / f"reference-{grasp}-seed{SEED}-{ITERATIONS}-machine.json"


def run_logs(grasp: str, out: Path, seed: int = SEED) -> dict[str, pd.DataFrame]:
    """Run a reference trial into `out`; its two logs by kind."""
    from experiments.analysis.logs import read_log
    from experiments.run.trial import run_trial

    run_trial(out, settings(grasp, seed), progress=False)
    return {kind: read_log(out, kind) for kind in ("iterations", "words")}


def machine_differences(grasp: str) -> list[str]:
    """What differs between this machine and the one that recorded a trial's logs, in what can
    change its bits (the commit aside: the logs are what the code must keep giving)."""
    from experiments.trial_dir.provenance import bit_differences, machine_record

    path = machine_path(grasp)
    if not path.exists():
        return [f"no record of the machine that recorded them ({path.name})"]
    recorded = json.loads(path.read_text())
    return bit_differences({**recorded, "source": {}}, {**machine_record(), "source": {}})


def event_counts(log: pd.DataFrame) -> dict[str, int]:
    """What happened in a trial, counted over its iterations log."""
    from models.layout import TOYS

    counts = {"stick_grasps": int(log["stick_grasped"].sum())}
    for by in ("hand", "push", "stick", "caregiver"):
        counts[f"toys_moved_by_{by}"] = int(sum((log[f"{t}_moved_by"] == by).sum() for t in TOYS))
    counts["caregiver_said"] = int((log["caregiver_said"] != "").sum())
    counts["words_recognised"] = int((log["word_recognised"] != "").sum())
    return counts


def record_logs(grasps: tuple[str, ...] = GRASPS) -> None:
    from experiments.trial_dir.provenance import machine_record

    with tempfile.TemporaryDirectory() as tmp:
        for grasp in grasps:
            logs = run_logs(grasp, Path(tmp) / grasp)
            for kind, table in logs.items():
                table.to_parquet(log_path(grasp, kind), index=False)
            record = machine_record()
            machine_path(grasp).write_text(json.dumps(record, indent=2, sort_keys=True) + "\n")
            print(f"recorded {grasp}: {log_path(grasp, 'iterations').name}")


def record_spread() -> None:
    from experiments.trial_dir.provenance import machine_record

    counts = {}
    with tempfile.TemporaryDirectory() as tmp:
        for seed in SPREAD_SEEDS:
            logs = run_logs("physical", Path(tmp) / f"seed{seed}", seed)
            counts[str(seed)] = event_counts(logs["iterations"])
            print(f"seed {seed}: {counts[str(seed)]}")
    spread = {
        "what": "event counts of the physical reference trial's settings under other seeds",
        "made_by": "tests/reference_trials.py spread",
        "machine": machine_record(),
        "counts_by_seed": counts,
    }
    SPREAD_FILE.write_text(json.dumps(spread, indent=2, sort_keys=True) + "\n")


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("what", choices=["logs", "spread"])
    parser.add_argument("--grasp", choices=GRASPS, help="record this backend's logs only")
    args = parser.parse_args(argv)
    if args.what == "logs":
        record_logs((args.grasp,) if args.grasp else GRASPS)
    else:
        record_spread()
    return 0


if __name__ == "__main__":
    sys.exit(main())
