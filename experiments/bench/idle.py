"""How this machine treats code left idle: the Python a physical iteration runs after its MuJoCo
steps, timed back to back and right after those steps or a Python busy loop as long.

Why: on the shared development machine these calls took 19 us back to back and 222 us right
after 500 `mj_step` (README, *Speed*), and the physical ratio carries that; a kinematic
iteration never leaves its Python idle. These figures tell a machine where that
holds from one where it does not.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Iterator

import numpy as np

from models.layout import ARM_DIM, N_STEPS
from sim import Playroom
from sim import events as ev
from sim.mujoco_import import mujoco
from sim.physics import CONTROL_SUBSTEPS

_SAMPLES = 200  # timings of the calls after each kind of gap; their median is printed


def idle_figures(seed: int = 0) -> Iterator[tuple[str, float, str]]:
    """Median time of a physical iteration's after-step calls, back to back and after a gap."""
    room = Playroom(grasp="physical", seed=seed)
    rng = np.random.default_rng(seed)
    for _ in range(20):  # a room that has moved, as in a trial
        room.act_arm(rng.uniform(-1.0, 1.0, ARM_DIM))
    p = room.physics
    positions = np.repeat(p.tracked_positions()[None], N_STEPS + 1, axis=0)

    def after_steps() -> None:  # what `Playroom._run` and its feedback call after the steps
        ev.movement_events(positions, [], None)
        room.backend.stick_out_of_reach(p)
        room.get_state()
        p.tracked_positions()

    steps = mujoco.MjData(p.model.ptr)  # stepped aside: the room's own state is not touched
    n_steps = N_STEPS * CONTROL_SUBSTEPS
    start = time.perf_counter()
    mujoco.mj_step(p.model.ptr, steps, n_steps)
    step_s = time.perf_counter() - start

    def busy() -> None:  # Python only, for as long as the steps took
        end = time.perf_counter() + step_s
        while time.perf_counter() < end:
            pass

    back_to_back = _median_after(after_steps, lambda: None)
    after_mujoco = _median_after(after_steps, lambda: mujoco.mj_step(p.model.ptr, steps, n_steps))
    after_busy = _median_after(after_steps, busy)
    yield "after_step_calls_back_to_back", back_to_back * 1e6, "us"
    yield f"after_step_calls_after_{n_steps}_mj_step", after_mujoco * 1e6, "us"
    yield "after_step_calls_after_as_long_a_python_loop", after_busy * 1e6, "us"
    yield "after_step_calls_after_mj_step_over_back_to_back", after_mujoco / back_to_back, "ratio"


def _median_after(calls: Callable[[], None], gap: Callable[[], object]) -> float:
    times = []
    for _ in range(_SAMPLES):
        gap()
        start = time.perf_counter()
        calls()
        times.append(time.perf_counter() - start)
    return float(np.median(times))
