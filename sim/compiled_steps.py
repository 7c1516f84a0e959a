"""A physical movement's control steps in compiled code (numba) calling MuJoCo's C library.

Why: a physical iteration is 500 MuJoCo steps in 50 control steps, and each control step cost
4-7 us of Python around MuJoCo's own work (setting the servos' targets, three calls into the
bindings, reading the tracked positions and the contacts): up to a sixth of an arm iteration
(`playroom bench world` measured the compiled loop at 0.81 of the Python one, docs/speed.md,
before the Python loop moved to tests/stepped_oracle.py). Here one
compiled loop runs the control steps and returns to Python only when a contact the grasp acts
on appears (the grasp's rules stay in sim/grasping/physical.py).

Same numbers: the loop calls the same C functions in the same order as
`PlayroomPhysics.advance` (mj_step2, then mj_step, then mj_step1), writes the servos' targets
and the caregiver's hand as the physical backend writes them (each operation rounded on its
own, no fast-math), and reads positions and contact sensors from the same arrays. The sensors
are off during a control step's first substeps (`disable_flags_view`): they feed nothing back
into the dynamics, and are read only after the last.
tests/sim/test_compiled_steps.py holds it to the step-by-step Python loop (tests/sim/
stepped_oracle.py) bit for bit.

MuJoCo's library is the one its Python package ships (found beside `mujoco/__init__.py`); where
it is not found, `AVAILABLE` is False and a physical room cannot be built (`MISSING`).
"""

from __future__ import annotations

import ctypes
import glob
import os
from typing import Any

import numpy as np
from llvmlite import binding
from numba import types

from sim.compiled import compiled
from sim.mujoco_import import mujoco


def _mujoco_library() -> str | None:
    """Path of the MuJoCo shared library inside the mujoco package, or None."""
    folder = os.path.dirname(mujoco.__file__)
    for pattern in ("libmujoco.so*", "libmujoco*.dylib", "mujoco.dll"):
        found = sorted(glob.glob(os.path.join(folder, pattern)))
        if found:
            return found[0]
    return None


LIBRARY = _mujoco_library()
AVAILABLE = LIBRARY is not None
MISSING = (
    "the physical backend steps MuJoCo from compiled code and needs MuJoCo's shared library "
    f"beside the mujoco package ({os.path.dirname(mujoco.__file__)}): none was found there; "
    "reinstall mujoco from its wheel (pip install --force-reinstall mujoco)"
)
if AVAILABLE:
    # The symbols the compiled code links to (numba's cache stores the calls by name).
    binding.load_library_permanently(LIBRARY)

# void mj_step*(const mjModel* m, mjData* d): the pointers passed as integers of their width.
_STEP_SIGNATURE = types.void(types.uintp, types.uintp)
mj_step: Any = types.ExternalFunction("mj_step", _STEP_SIGNATURE)
mj_step1: Any = types.ExternalFunction("mj_step1", _STEP_SIGNATURE)
mj_step2: Any = types.ExternalFunction("mj_step2", _STEP_SIGNATURE)
# void mj_getState(m, d, mjtNum* state, int sig) and mj_setState(m, d, const mjtNum*, int sig)
_STATE_SIGNATURE = types.void(types.uintp, types.uintp, types.uintp, types.intc)
mj_getState: Any = types.ExternalFunction("mj_getState", _STATE_SIGNATURE)
mj_setState: Any = types.ExternalFunction("mj_setState", _STATE_SIGNATURE)

# What a control step starting from a state computes from (MuJoCo's "integration" state, which
# reproduces a step), less the time, which nothing in the room's dynamics reads.
_TIME = int(mujoco.mjtState.mjSTATE_TIME)
DYNAMIC_STATE = int(mujoco.mjtState.mjSTATE_INTEGRATION) & ~_TIME


# mjOption's fields that follow `gravity` and precede `disableflags` span about 230 bytes.
_OPTION_WINDOW_INTS = 128
SENSORS_OFF = int(mujoco.mjtDisableBit.mjDSBL_SENSOR)


def disable_flags_view(model: mujoco.MjModel) -> np.ndarray | None:
    """A (1,) int32 array over `model.opt.disableflags` in the model's own memory, through
    which the compiled loop switches sensors off between control steps; None where it cannot
    be found (the loop then computes them at every step: the same numbers, slower).

    The bindings expose no address for an integer field of mjOption: it is found by changing
    the field through the bindings and seeing which int changed in the memory that follows
    `opt.gravity` (an array of the same struct, whose address they do expose); the field is
    put back at once.
    """
    gravity = model.opt.gravity.__array_interface__["data"][0]
    window = np.ctypeslib.as_array((ctypes.c_int32 * _OPTION_WINDOW_INTS).from_address(gravity))
    before = window.copy()
    original = model.opt.disableflags
    model.opt.disableflags = original ^ SENSORS_OFF
    changed = np.flatnonzero(window != before)
    model.opt.disableflags = original
    if len(changed) != 1 or window[changed[0]] != original:
        return None
    return window[changed[0] : changed[0] + 1]


@compiled
def control_steps(
    model: int,
    data: int,
    substeps: int,
    start: int,
    arm_targets: np.ndarray,
    ctrl: np.ndarray,
    brought: np.ndarray,
    hand_mocap: np.ndarray,
    site_xpos: np.ndarray,
    site_indices: np.ndarray,
    xpos: np.ndarray,
    body_indices: np.ndarray,
    positions: np.ndarray,
    sensordata: np.ndarray,
    watched: np.ndarray,
    disable_flags: np.ndarray,
    rest: np.ndarray,
    warnings: np.ndarray,
    timestep: float,
    computed: np.ndarray,
    qpos: np.ndarray,
    mocap_pos: np.ndarray,
    qpos_trace: np.ndarray,
    mocap_trace: np.ndarray,
) -> int:  # pragma: no cover - compiled; tested against the Python loop
    """Control steps `start`, `start` + 1, ... of a movement, each `substeps` MuJoCo steps.

    model, data: the addresses of the MjModel and MjData. arm_targets (n, nu): the servos'
    targets written to ctrl (nu,) before each step, or (0, nu) to leave them. brought (n, 2):
    where the caregiver's hand (hand_mocap, its mocap_pos row) is put before each step (her
    path, sim/caregiver.py), or (0, 2) if she brings nothing. After each step row k + 1 of positions
    (n + 1, m) takes the flat site_xpos at `site_indices`, then the flat xpos at
    `body_indices` (m in all), as `PlayroomPhysics.write_tracked_positions` reads them.
    Returns the first step k after which a sensor at an address in `watched` is positive, or n.

    disable_flags (1,): the model's opt.disableflags (`disable_flags_view`), through which the
    sensors, read only after a control step, are off during its first substeps (they feed
    nothing back into the dynamics); or (0,) to leave them on.

    rest (2, mj_stateSize(DYNAMIC_STATE)): room for two states. With no targets and no one
    bringing, every control step starts from the same inputs; once one leaves the state
    (DYNAMIC_STATE) bit for bit as it found it and raises no warning (everything at rest),
    every later one would too: they are not computed, the time (`timestep` per MuJoCo step)
    advances as MuJoCo's additions would advance it and their positions are the last ones.
    warnings: MuJoCo's warning counts (mjData.warning's `number`). computed[0] grows by one per
    control step computed.

    qpos (nq,), mocap_pos (nmocap * 3,): the data's, flat. Where qpos_trace (n + 1, nq) and
    mocap_trace (n + 1, nmocap * 3) have rows (a movement's trace, sim/movement.py), row k + 1
    takes them after step k; with (0, ...) nothing is traced.
    """
    n = positions.shape[0] - 1
    tracing = qpos_trace.shape[0] > 0
    switch = disable_flags.shape[0] > 0
    flags = disable_flags[0] if switch else 0
    n_sites = site_indices.shape[0]
    may_rest = arm_targets.shape[0] == 0 and brought.shape[0] == 0
    before, after = rest[0], rest[1]
    warned = 0
    if may_rest:
        mj_getState(model, data, before.ctypes.data, DYNAMIC_STATE)
    for k in range(start, n):
        if arm_targets.shape[0] > 0:
            for j in range(ctrl.shape[0]):
                ctrl[j] = arm_targets[k, j]
        if brought.shape[0] > 0:
            for i in range(2):
                hand_mocap[i] = brought[k, i]
        if may_rest:
            warned = warnings.sum()
        if switch:
            disable_flags[0] = flags | SENSORS_OFF
        mj_step2(model, data)
        for _ in range(substeps - 1):
            mj_step(model, data)
        if switch:
            disable_flags[0] = flags
        mj_step1(model, data)
        computed[0] += 1
        for i in range(n_sites):
            positions[k + 1, i] = site_xpos[site_indices[i]]
        for i in range(body_indices.shape[0]):
            positions[k + 1, n_sites + i] = xpos[body_indices[i]]
        if tracing:
            qpos_trace[k + 1] = qpos
            mocap_trace[k + 1] = mocap_pos
        for address in watched:
            if sensordata[address] > 0:
                return k
        if may_rest and k + 1 < n:
            mj_getState(model, data, after.ctypes.data, DYNAMIC_STATE)
            if warnings.sum() == warned and _same_bits(before, after):
                _rest_until(model, data, n - 1 - k, substeps, timestep, positions, k + 1)
                if tracing:
                    for row in range(k + 2, n + 1):
                        qpos_trace[row] = qpos_trace[k + 1]
                        mocap_trace[row] = mocap_trace[k + 1]
                return n
            before, after = after, before
    return n


@compiled
def _same_bits(a: np.ndarray, b: np.ndarray) -> bool:  # pragma: no cover - compiled
    """Whether two float64 vectors hold the same bits (0.0 and -0.0 differ, a NaN never
    matches: a state holding one is not at rest)."""
    a_bits, b_bits = a.view(np.int64), b.view(np.int64)
    for i in range(a_bits.shape[0]):
        if a_bits[i] != b_bits[i] or a[i] != a[i]:
            return False
    return True


@compiled
def _rest_until(
    model: int,
    data: int,
    remaining: int,
    substeps: int,
    timestep: float,
    positions: np.ndarray,
    row: int,
) -> None:  # pragma: no cover - compiled; tested against the Python loop
    """The end of `remaining` control steps at rest: MuJoCo's time advanced by one
    `timestep` addition per step, as mj_step advances it, and their positions row's copies."""
    time = np.empty(1)
    mj_getState(model, data, time.ctypes.data, _TIME)
    for _ in range(remaining * substeps):
        time[0] = time[0] + timestep
    mj_setState(model, data, time.ctypes.data, _TIME)
    for k in range(row + 1, row + 1 + remaining):
        positions[k] = positions[row]
