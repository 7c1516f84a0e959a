"""A physical movement's control steps in compiled code (numba) calling MuJoCo's C library.

Why: a physical iteration is 500 MuJoCo steps in 50 control steps, and each control step cost
4-7 us of Python around MuJoCo's own work (setting the servos' targets, three calls into the
bindings, reading the tracked positions and the contacts): up to a sixth of an arm iteration
(`playroom bench world`, `physical_arm_iteration_compiled_over_python_steps`). Here one
compiled loop runs the control steps and returns to Python only when a contact the grasp acts
on appears (the grasp's rules stay in sim/grasping/physical.py).

Same numbers: the loop calls the same C functions in the same order as
`PlayroomPhysics.advance` (mj_step2, then mj_step, then mj_step1), writes the servos' targets
and the caregiver's hand as the physical backend writes them (each operation rounded on its
own, no fast-math), and reads positions and contact sensors from the same arrays. The sensors
are off during a control step's first substeps (`disable_flags_view`): they feed nothing back
into the dynamics, and are read only after the last.
tests/world/test_compiled_steps.py holds it to the step-by-step Python loop bit for bit.

MuJoCo's library is the one its Python package ships (found beside `mujoco/__init__.py`); where
it is not found, `AVAILABLE` is False and the room steps in Python.
"""

from __future__ import annotations

import ctypes
import glob
import os
from typing import Any

import mujoco
import numpy as np
from llvmlite import binding
from numba import types

from sim.compiled import compiled


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
if AVAILABLE:
    # The symbols the compiled code links to (numba's cache stores the calls by name).
    binding.load_library_permanently(LIBRARY)

# void mj_step*(const mjModel* m, mjData* d): the pointers passed as integers of their width.
_STEP_SIGNATURE = types.void(types.uintp, types.uintp)
mj_step: Any = types.ExternalFunction("mj_step", _STEP_SIGNATURE)
mj_step1: Any = types.ExternalFunction("mj_step1", _STEP_SIGNATURE)
mj_step2: Any = types.ExternalFunction("mj_step2", _STEP_SIGNATURE)


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
    bring_to: np.ndarray,
    bring_rate: float,
    hand_mocap: np.ndarray,
    site_xpos: np.ndarray,
    site_indices: np.ndarray,
    xpos: np.ndarray,
    body_indices: np.ndarray,
    positions: np.ndarray,
    sensordata: np.ndarray,
    watched: np.ndarray,
    disable_flags: np.ndarray,
) -> int:  # pragma: no cover - compiled; tested against the Python loop
    """Control steps `start`, `start` + 1, ... of a movement, each `substeps` MuJoCo steps.

    model, data: the addresses of the MjModel and MjData. arm_targets (n, nu): the servos'
    targets written to ctrl (nu,) before each step, or (0, nu) to leave them. bring_to (2,):
    where the caregiver's hand (hand_mocap, its mocap_pos row) moves `bring_rate` of the way
    before each step, or (0,) if she brings nothing. After each step row k + 1 of positions
    (n + 1, m) takes the flat site_xpos at `site_indices`, then the flat xpos at
    `body_indices` (m in all), as `PlayroomPhysics.write_tracked_positions` reads them.
    Returns the first step k after which a sensor at an address in `watched` is positive, or n.

    disable_flags (1,): the model's opt.disableflags (`disable_flags_view`), through which the
    sensors, read only after a control step, are off during its first substeps (they feed
    nothing back into the dynamics); or (0,) to leave them on.
    """
    n = positions.shape[0] - 1
    switch = disable_flags.shape[0] > 0
    flags = disable_flags[0] if switch else 0
    n_sites = site_indices.shape[0]
    for k in range(start, n):
        if arm_targets.shape[0] > 0:
            for j in range(ctrl.shape[0]):
                ctrl[j] = arm_targets[k, j]
        if bring_to.shape[0] > 0:
            for i in range(2):
                here = hand_mocap[i]
                hand_mocap[i] = here + bring_rate * (bring_to[i] - here)
        if switch:
            disable_flags[0] = flags | SENSORS_OFF
        mj_step2(model, data)
        for _ in range(substeps - 1):
            mj_step(model, data)
        if switch:
            disable_flags[0] = flags
        mj_step1(model, data)
        for i in range(n_sites):
            positions[k + 1, i] = site_xpos[site_indices[i]]
        for i in range(body_indices.shape[0]):
            positions[k + 1, n_sites + i] = xpos[body_indices[i]]
        for address in watched:
            if sensordata[address] > 0:
                return k
    return n
