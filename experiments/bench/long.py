"""`playroom bench long`: the cost of development longer than the study's, measured on one
trial of 10^6 iterations: its cost per iteration and the bytes a checkpoint writes
near 80000 iterations and near its end, from the memory segments it writes every 1000
iterations (their write times and sizes), and its peak memory; then each model's inverse query
on its final memories, scanned whole and through the nearest-neighbour index. One trial in a
process of its own, run as `playroom run` runs it (study preset, kinematic, seed 0), in a
temporary directory.

Why from the segments: a trial writes one per checkpoint period, so their times are the
trial's own clock at every 1000 iterations, with nothing added to the trial to measure it.
"""

from __future__ import annotations

import math
import os
import subprocess
import sys
import tempfile
import time
from collections.abc import Iterator
from pathlib import Path

import numpy as np

from experiments.trial_dir.reading import open_for_reading
from learner.memory import TREE_ROWS, NearestNeighbourMemory
from learner.sensorimotor_model import MODELS, ModelSpec
from models.layout import BLOCK_DIM

LONG_ITERATIONS = 1_000_000
NEAR = 80_000  # the study's length: the reference point
WINDOW = 8_000  # iterations each cost is averaged over
PERIOD = 1_000  # the trial's checkpoint period: one segment each
# The targets of long development: cost and checkpoint bytes at 10^6 over 80000, peak memory.
COST_RATIO_TARGET = 2.0
BYTES_RATIO_TARGET = 1.5
PEAK_MEMORY_TARGET_MB = 4096
# And checking every file of the trial against its manifest, under a second.
MANIFEST_CHECK_TARGET_S = 1.0
_NO_TREES = 2**62  # a memory that never sorts its rows into trees: the whole scan
# The child prints its own peak resident memory after the trial (kB on Linux).
_CHILD = (
    "import resource, sys; from experiments.cli.main import main; rc = main(sys.argv[1:]); "
    "print('peak_kb', resource.getrusage(resource.RUSAGE_SELF).ru_maxrss); sys.exit(rc)"
)


def long_figures(
    iterations: int = LONG_ITERATIONS, near: int = NEAR, window: int = WINDOW
) -> Iterator[tuple[str, float, str]]:
    """(name, value, unit) of one trial of `iterations`: cost per iteration over the `window`
    iterations from `near` and up to the last period, the checkpoint bytes at both, and the
    trial's peak memory."""
    with tempfile.TemporaryDirectory(prefix="playroom-bench-long-") as scratch:
        out = Path(scratch) / "trial"
        command = [sys.executable, "-c", _CHILD, "run", "--out", str(out)]
        command += ["--iterations", str(iterations), "--checkpoint-every", str(PERIOD)]
        command += ["--preset", "study", "--seed", "0"]
        done = subprocess.run([*command, "--quiet"], capture_output=True, text=True)
        if done.returncode != 0:
            raise RuntimeError(f"the long trial failed: {done.stderr.strip()[-500:]}")
        peak_kb = int(done.stdout.split("peak_kb")[-1].split()[0])
        late = iterations - PERIOD - window  # the last segment is the last period's
        early_cost, late_cost = (_cost(out, start, window) for start in (near, late))
        early_bytes, late_bytes = (_checkpoint_bytes(out, start) for start in (near, late))
        queries = list(query_figures(out))
        checks = list(manifest_figures(out))
    yield f"long_cost_per_iteration_near_{near}", early_cost * 1e3, "ms"
    yield f"long_cost_per_iteration_near_{iterations}", late_cost * 1e3, "ms"
    ratio = late_cost / early_cost
    yield "long_cost_ratio", ratio, f"ratio (target <= {COST_RATIO_TARGET:g})"
    yield f"long_checkpoint_bytes_near_{near}", early_bytes / 1e3, "kB"
    yield f"long_checkpoint_bytes_near_{iterations}", late_bytes / 1e3, "kB"
    bytes_ratio = late_bytes / early_bytes
    yield "long_checkpoint_bytes_ratio", bytes_ratio, f"ratio (target <= {BYTES_RATIO_TARGET:g})"
    yield "long_peak_memory", peak_kb / 1024, f"MB (target < {PEAK_MEMORY_TARGET_MB})"
    yield from queries
    yield from checks


def manifest_figures(trial: Path, passes: int = 3) -> Iterator[tuple[str, float, str]]:
    """What checking the trial's files against its manifest costs
    (experiments/trial_dir/manifest.py), the best of `passes`: reading its chain and every file's
    presence and size, as a reader does before it starts; and every file's SHA-256 besides, as all
    readers together do."""
    check, every, files, size = math.inf, math.inf, 0, 0
    for _ in range(passes):
        start = time.perf_counter()
        recorded = open_for_reading(trial).file_manifest()
        if recorded is None:
            raise RuntimeError(f"{trial} recorded no manifest")
        recorded.check_present()
        middle = time.perf_counter()
        size = sum(len(recorded.read_bytes(trial / name, "")) for name in recorded.files)
        check, every = min(check, middle - start), min(every, time.perf_counter() - start)
        files = len(recorded.files)
    yield "long_manifest_check", check, f"s ({files} files: chain, presence and sizes)"
    yield (
        "long_manifest_checksums",
        every,
        (f"s ({files} files, {size / 1e6:.0f} MB hashed; target < {MANIFEST_CHECK_TARGET_S:g})"),
    )


def query_figures(
    trial: Path, n_queries: int = 300, passes: int = 3
) -> Iterator[tuple[str, float, str]]:
    """Each model's inverse query on the trial's final memories, scanned whole and through the
    trees (learner/code_tree.py), the same answers asserted: microseconds a query, the best
    of `passes` over `n_queries` goals (uniform in [-1, 1]^10, with a stored row's context),
    and their mean over the models that hold rows (random babbling's choice). Then how the
    query grows: each model of at least 4 x TREE_ROWS rows, on its first 2 x TREE_ROWS x 2^k
    rows, as it was when it held them."""
    state = open_for_reading(trial).agent_state()
    rng = np.random.default_rng(0)
    keys = {s.number: state[f"model{s.number}.key"] for s in MODELS}
    held = [spec for spec in MODELS if len(keys[spec.number])]
    means = {"scan": 0.0, "trees": 0.0}
    for spec in held:
        rows = keys[spec.number]
        seconds = _query_seconds(spec, rows, rng, n_queries, passes)
        for name in ("scan", "trees"):
            means[name] += seconds[name] / len(held)
            unit = f"us ({len(rows)} rows of {rows.shape[1]})"
            yield f"long_query_model{spec.number}_{name}", 1e6 * seconds[name], unit
    for name in ("scan", "trees"):
        yield f"long_query_mean_{name}", 1e6 * means[name], "us"
    for spec in held:
        rows = keys[spec.number]
        n = 2 * TREE_ROWS
        while len(rows) >= 4 * TREE_ROWS and n < len(rows):
            seconds = _query_seconds(spec, rows[:n], rng, n_queries, passes)
            for name in ("scan", "trees"):
                yield f"long_query_model{spec.number}_{name}_at_{n}_rows", 1e6 * seconds[name], "us"
            n *= 2


def _query_seconds(
    spec: ModelSpec, rows: np.ndarray, rng: np.random.Generator, n_queries: int, passes: int
) -> dict[str, float]:
    """{'scan': s, 'trees': s}: seconds of a query of model `spec` holding `rows`, scanned
    whole and through the trees; AssertionError if the two answer otherwise."""
    context = rows[rng.integers(0, len(rows), n_queries), : len(spec.context_dims)]
    queries = np.hstack((context, rng.uniform(-1.0, 1.0, (n_queries, BLOCK_DIM))))
    answers, seconds = {}, {}
    for name, tree_rows in (("scan", _NO_TREES), ("trees", TREE_ROWS)):
        memory = NearestNeighbourMemory(rows.shape[1], tree_rows=tree_rows)
        memory.extend(rows)
        answers[name] = [memory.nearest_index(q) for q in queries]
        seconds[name] = min(_time_queries(memory, queries) for _ in range(passes))
    if answers["scan"] != answers["trees"]:
        raise AssertionError(f"model {spec.number}: the trees answered otherwise")
    return seconds


def _time_queries(memory: NearestNeighbourMemory, queries: np.ndarray) -> float:
    """Seconds a query, over `queries` one after the other."""
    start = time.perf_counter()
    for q in queries:
        memory.nearest_index(q)
    return (time.perf_counter() - start) / len(queries)


def _segment(trial: Path, start: int) -> Path:
    return open_for_reading(trial).segment_path(start)


def _cost(trial: Path, start: int, window: int) -> float:
    """Seconds per iteration between the segments written at `start` and `start + window`."""
    first, last = _segment(trial, start), _segment(trial, start + window)
    return (os.path.getmtime(last) - os.path.getmtime(first)) / window


def _checkpoint_bytes(trial: Path, start: int) -> int:
    """What one checkpoint writes there: the period's segment, its manifest file and a
    checkpoint (the final one's size: a checkpoint's size does not grow with the trial)."""
    end, reading = start + PERIOD, open_for_reading(trial)
    files = (_segment(trial, start), reading.manifest_path(end), reading.checkpoint_path)
    return sum(p.stat().st_size for p in files)
