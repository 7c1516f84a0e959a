"""A trial's progress bar (tqdm), whose rate and time left are the trial's pace: an iteration
slower than STALL_SECONDS is a compiled kernel being loaded, or compiled on the first run of a
fresh install (numba: about 20 s spread over a process's first movements and stores), not the
pace of the trial, and the bar leaves its time out of its rate, its time left and its elapsed
time. A movement takes milliseconds; without this, a first trial's bar showed eleven hours
left after its first iteration."""

from __future__ import annotations

import time

from tqdm import tqdm

STALL_SECONDS = 1.0
clock = time.perf_counter  # the clock that times an iteration (replaced in tests)


def trial_bar(total: int, initial: int, progress: bool, desc: str) -> tqdm:
    """The bar of a trial's iterations, from `initial` (a resumed trial's) to `total`."""
    return tqdm(
        total=total,
        initial=initial,
        disable=not progress,
        unit="it",
        desc=desc,
        dynamic_ncols=True,
    )


def leave_out_stall(bar: tqdm, seconds: float) -> None:
    """Leave an iteration's `seconds` out of the bar's timing where it stalled (module
    docstring): as if the bar had been paused for them (tqdm's own `unpause`, which shifts
    the same two clocks)."""
    if seconds > STALL_SECONDS and not bar.disable:
        bar.start_t += seconds
        bar.last_print_t += seconds
