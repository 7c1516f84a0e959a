"""What a trial will cost, said before it starts: its time, and the disk its files take.

The disk a trial holds at its end grows with its iterations: a row of logs each, and the
learner's memory, each row of it written once, in the segment of the checkpoint period that
stored it (experiments/trial_dir/memory_segments.py), beside two checkpoints of a fixed size. The
bytes it writes grow as the disk does, in proportion to the iterations (before segments, every
checkpoint rewrote every row: they grew with the square). Its time per iteration grows with the
learner's memory, less than in proportion to it since older rows are searched through trees
(learner/code_tree.py): the growth measured by `playroom bench long` between iterations 80000
and 10^6, a power of the iteration through those two figures, is the growth assumed at every
length beyond 80000 (`growth_seconds`).

The estimate rests on the costs measured on the development machine (docs/speed.md, its bench
figures at commit 1a4591c, and `playroom bench long` at eebcc93); on the study's 80000-iteration
trial it says 15 s, where 17.1 s were measured at 1a4591c and 9.5 s on 2026-11-25; on 10^6
iterations 4.2 min, where 3 min 25 s were measured (beside a second trial). Another machine
scales the time, not the disk. A trial that will not fit on its disk
is refused before anything is written, `--quiet` or not (`check_fits`).
"""

from __future__ import annotations

import math
import os
import shutil
from dataclasses import dataclass
from pathlib import Path

from experiments.run.settings import TrialSettings
from experiments.trial_dir.errors import TrialError
from experiments.trial_dir.reading import open_for_reading

# Seconds of an iteration, by grasp backend: 5293 and 559 iterations a second over trials of
# 5000 iterations (docs/speed.md, `playroom bench trial`, which measures every registered
# backend). A backend not measured here yet is estimated at the slowest's cost (`_per_iteration`).
SECONDS_PER_ITERATION = {"kinematic": 1 / 5293, "physical": 1 / 559}
# A kinematic trial's seconds per iteration near iteration 80000 and near 10^6, measured by
# `playroom bench long` at commit eebcc93 (docs/speed.md): how the learner's cost grows.
GROWTH_FROM = 80000
SECONDS_NEAR_GROWTH_FROM = 0.1327e-3
SECONDS_NEAR_A_MILLION = 0.2331e-3
# Bytes an iteration adds to the logs (docs/learning.md: about 120 KB per 1000 iterations) and to
# the memory's segments (585 measured over iterations 1000 to 20000 of a kinematic trial, seed 0,
# none during the study's bootstrap; 611 in earlier checkpoints, 416 MB at 681000: rounded up
# from the larger, as a disk that is too small fails a trial late).
LOG_BYTES_PER_ITERATION = 120
MEMORY_BYTES_PER_ITERATION = 620
# Bytes of a checkpoint without the memory's rows: 38.9 KB measured, at 3000 and at 20000
# iterations alike.
CHECKPOINT_BYTES = 40e3
# How fast a checkpoint is written: an 11 MB one took 19 to 23 ms.
CHECKPOINT_BYTES_PER_SECOND = 0.5e9
# Trials longer than the study's 80000 iterations state their estimate before they start.
LONG_TRIAL = 80000


@dataclass(frozen=True)
class TrialCosts:
    """What running a trial from an iteration to its end costs."""

    seconds: float
    disk_bytes: float  # its logs, memory segments and two checkpoints at the end
    written_bytes: float  # every checkpoint and memory segment written on the way, in all


def trial_costs(settings: TrialSettings, start: int = 0) -> TrialCosts:
    """The costs of running `settings`' trial from iteration `start` to its end."""
    n, s = settings.iterations, min(start, settings.iterations)
    # Each iteration's rows are written once; a checkpoint every `checkpoint_every`, and one at
    # the end.
    checkpoints = -(-(n - s) // settings.checkpoint_every)
    written = MEMORY_BYTES_PER_ITERATION * (n - s) + CHECKPOINT_BYTES * checkpoints
    seconds = (
        (n - s) * _per_iteration(settings.grasp)
        + growth_seconds(n)
        - growth_seconds(s)
        + written / CHECKPOINT_BYTES_PER_SECOND
    )
    disk = n * (LOG_BYTES_PER_ITERATION + MEMORY_BYTES_PER_ITERATION) + 2 * CHECKPOINT_BYTES
    return TrialCosts(seconds, disk, written)


def check_fits(out_dir: Path, settings: TrialSettings, resume: bool) -> str | None:
    """TrialError (one line) if the trial's files will not fit on the disk of `out_dir`, with
    what it holds there already; else the line that states a long trial's costs (trials longer
    than LONG_TRIAL iterations, with iterations left to run), or None."""
    start, held = open_for_reading(out_dir).progress() if resume else (0, 0)
    costs = trial_costs(settings, start)
    free = _free_space(_existing(out_dir))
    need = costs.disk_bytes - held
    basis = (
        f"estimated from the development machine's costs: "
        f"{1000 * _per_iteration(settings.grasp):.2g} ms an iteration, "
        f"plus the learner's growth beyond {GROWTH_FROM}: x{_GROWTH_RATIO:.2g} an iteration at "
        f"10^6, as `playroom bench long` measured, "
        f"{LOG_BYTES_PER_ITERATION} B of logs and {MEMORY_BYTES_PER_ITERATION} B of memory an "
        f"iteration, {size(CHECKPOINT_BYTES)} a checkpoint"
    )
    if free is not None and need > free:
        raise TrialError(
            f"this trial needs ~{size(need)} more of logs and checkpoints on {out_dir} "
            f"({size(free)} free): ask for fewer iterations, or another disk ({basis})"
        )
    if settings.iterations <= LONG_TRIAL or start >= settings.iterations:
        return None
    free_text = "?" if free is None else size(free)
    return (
        f"this trial: ~{duration(costs.seconds)}, ~{size(costs.disk_bytes)} of logs and "
        f"checkpoints on {out_dir} ({free_text} free); its checkpoints, each writing the "
        f"memory's new rows, write ~{size(costs.written_bytes)} in all ({basis})"
    )


def check_batch_fits(out_dir: Path, trials: list[tuple[Path, TrialSettings]]) -> str | None:
    """For a batch's trials still to run (each its directory and settings, resumed where they
    stand): TrialError (one line) if their files together will not fit on the disk of
    `out_dir`, before anything is written or a worker started; else the line that states a long
    batch's costs (its trials' seconds, if one process ran them all, and disk), or None."""
    costs, held = [], 0
    for trial_dir, settings in trials:
        start, on_disk = open_for_reading(trial_dir).progress() if trial_dir.is_dir() else (0, 0)
        costs.append(trial_costs(settings, start))
        held += on_disk
    need = sum(c.disk_bytes for c in costs) - held
    free = _free_space(_existing(out_dir))
    if free is not None and need > free:
        raise TrialError(
            f"this batch's {len(trials)} trial(s) to run need ~{size(need)} more of logs and "
            f"checkpoints on {out_dir} ({size(free)} free): ask for fewer iterations or seeds, "
            "or another disk (the development machine's costs: docs/speed.md)"
        )
    seconds = sum(c.seconds for c in costs)
    if not trials or max(s.iterations for _, s in trials) <= LONG_TRIAL:
        return None
    return (
        f"this batch: {len(trials)} trial(s) to run, ~{duration(seconds)} on one core in all "
        f"(divide by the workers), ~{size(need)} of logs and checkpoints on {out_dir}"
    )


_GROWTH_RATIO = SECONDS_NEAR_A_MILLION / SECONDS_NEAR_GROWTH_FROM
# The power of the iteration the measured cost per iteration follows between the two figures.
_GROWTH_POWER = math.log(_GROWTH_RATIO) / math.log(1e6 / GROWTH_FROM)


def growth_seconds(iterations: int) -> float:
    """Seconds the learner's growth adds over a trial's first `iterations`, above its cost
    near GROWTH_FROM: the integral of c (i / GROWTH_FROM)^p - c from GROWTH_FROM on, c and p
    through the two measured figures."""
    if iterations <= GROWTH_FROM:
        return 0.0
    x, p = iterations / GROWTH_FROM, _GROWTH_POWER
    return SECONDS_NEAR_GROWTH_FROM * GROWTH_FROM * ((x ** (p + 1) - 1) / (p + 1) - (x - 1))


def _per_iteration(grasp: str) -> float:
    """Seconds of an iteration of a backend; a backend not measured yet, the slowest's."""
    return SECONDS_PER_ITERATION.get(grasp, max(SECONDS_PER_ITERATION.values()))


def _free_space(folder: Path) -> int | None:
    """Bytes free for files in `folder`; None where the system cannot say or nothing can be
    written (a pseudo file system such as /proc, a read-only one): the directory's own checks
    then say what is wrong."""
    usage = shutil.disk_usage(folder)
    if usage.total == 0 or not os.access(folder, os.W_OK):
        return None
    return usage.free


def _existing(path: Path) -> Path:
    """`path`, or its nearest parent that exists: where its files would go."""
    path = Path(os.path.abspath(path))
    while not path.exists() and path != path.parent:
        path = path.parent
    return path


def size(n_bytes: float) -> str:
    """'96 MB', '1.36 TB': decimal units, three significant digits."""
    for unit, scale in (("PB", 1e15), ("TB", 1e12), ("GB", 1e9), ("MB", 1e6), ("KB", 1e3)):
        if n_bytes >= scale:
            return f"{_number(n_bytes / scale)} {unit}"
    return f"{n_bytes:.0f} B"


def duration(seconds: float) -> str:
    """'40 s', '12 min', '3.2 h', '5.1 days', '35 years'."""
    for unit, scale in (("years", 365.25 * 86400), ("days", 86400), ("h", 3600), ("min", 60)):
        if seconds >= 2 * scale:
            return f"{_number(seconds / scale)} {unit}"
    return f"{_number(seconds)} s"


def _number(value: float) -> str:
    """Three significant digits, without an exponent: '1.36', '35', '1200'."""
    return f"{value:.3g}" if value < 1000 else f"{value:.0f}"
