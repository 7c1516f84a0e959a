"""Exact formants: VTL's area function and the resonances of a lossless tube.

The first two peaks of VTL's transfer function jump when peaks merge and vanish when the tongue
nearly closes the tract, so they make a discontinuous map of the articulators. Instead:

1. VTL gives the area function of the tract (`tract_state_to_tube_state`, 40 sections from the
   glottis to the lips, lengths in cm, areas in cm^2).
2. Every area is raised to at least MIN_AREA (0.25 cm^2), which keeps the tract open (VTL's own
   vowels have no section below 0.25 cm^2, so their formants are unchanged).
3. The tube is closed at the glottis and open at the lips, with a radiation end correction of
   LIP_END_CORRECTION lip radii. Its chain (ABCD) matrix from glottis to lips, lossless, gives
   U_glottis = D(f) U_lips when the lip pressure is zero, so the resonances are the zeros of the
   real function D(f). D(0) = 1 and the zeros are simple, so F1 and F2 are the first two sign
   changes of D on a fine frequency grid, located by linear interpolation. D depends smoothly on
   the areas, hence so do F1 and F2.

Against VTL's transfer-function peaks (8192 samples) of the speaker's /o u i e y/ this agrees
within about 11% (worst: F2 of /e/); see tests/sim/vocal/test_vocal.py.

When VTL raises an error, or D has fewer than two sign changes below MAX_FREQUENCY, or a value
is not finite, the frame gets FALLBACK_HZ (a uniform 17.5 cm tube: 500, 1500 Hz) and its `ok`
flag is False; callers count these events. No NaN ever leaves this module.
"""

from __future__ import annotations

import numpy as np
import vocaltractlab_cython as vtl

MIN_AREA = 0.25  # cm^2
LIP_END_CORRECTION = 0.8  # lip radii added to the last section (radiation inertance)
SOUND_SPEED = 35000.0  # cm/s, warm humid air
FREQ_STEP = 10.0  # Hz; linear interpolation of the crossing is then within 0.001 log2 of 5 Hz
MAX_FREQUENCY = 4000.0  # Hz, search limit (F2 stayed below 2750 Hz in 33000 box samples)
FREQ_GRID = np.arange(FREQ_STEP, MAX_FREQUENCY + FREQ_STEP / 2, FREQ_STEP)  # Hz
FALLBACK_HZ = (500.0, 1500.0)  # (F1, F2) of a uniform 17.5 cm tube: c / 4L, 3c / 4L
FALLBACK_LOG2 = np.log2(np.array(FALLBACK_HZ))
N_SECTIONS = 40
CHUNK = 256  # frames per vectorised block, to bound memory (CHUNK x grid x 8 bytes per array)


def tube_formants(
    lengths: np.ndarray, areas: np.ndarray, min_area: float = MIN_AREA
) -> tuple[np.ndarray, np.ndarray]:
    """F1, F2 (Hz) of lossless tubes, closed at the glottis and open at the lips.

    lengths, areas: (..., n_sections), glottis first, in cm and cm^2. Areas are raised to
    min_area. Returns formants (..., 2) in Hz and ok (...,) bool; frames that are not ok
    (non-positive area, fewer than two resonances below MAX_FREQUENCY, non-finite input) hold
    FALLBACK_HZ.
    """
    lengths = np.asarray(lengths, dtype=float)
    areas = np.asarray(areas, dtype=float)
    batch = lengths.shape[:-1]
    flat_l = lengths.reshape(-1, lengths.shape[-1])
    flat_a = np.maximum(areas.reshape(-1, areas.shape[-1]), min_area)
    out = np.empty((flat_l.shape[0], 2))
    ok = np.empty(flat_l.shape[0], dtype=bool)
    for start in range(0, flat_l.shape[0], CHUNK):
        sl = slice(start, start + CHUNK)
        out[sl], ok[sl] = _tube_formants_flat(flat_l[sl], flat_a[sl])
    return out.reshape(*batch, 2), ok.reshape(batch)


def _tube_formants_flat(lengths: np.ndarray, areas: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(B, S), (B, S) -> (B, 2) Hz, (B,) ok. See tube_formants."""
    with np.errstate(all="ignore"):
        valid = np.all(np.isfinite(lengths), axis=1) & np.all(np.isfinite(areas), axis=1)
        valid &= np.all(areas > 0, axis=1)
        safe_a = np.where(valid[:, None], areas, 1.0)
        safe_l = np.where(valid[:, None], lengths, 1.0)
        # The radiation mass of the lip opening acts like a slightly longer last section.
        safe_l = safe_l.copy()
        safe_l[:, -1] += LIP_END_CORRECTION * np.sqrt(safe_a[:, -1] / np.pi)
        k = 2.0 * np.pi * FREQ_GRID / SOUND_SPEED  # (F,) wavenumbers, rad/cm
        # Bottom row (C, D) of the chain matrix product, with the imaginary unit of C factored
        # out so everything is real; the characteristic impedance rho*c cancels in D's zeros.
        c = np.zeros((lengths.shape[0], FREQ_GRID.size))
        d = np.ones_like(c)
        for s in range(lengths.shape[1]):
            phase = safe_l[:, s, None] * k
            cs, sn = np.cos(phase), np.sin(phase)
            a = safe_a[:, s, None]
            c, d = c * cs + d * sn * a, d * cs - c * sn / a
        flips = np.signbit(d[:, :-1]) != np.signbit(d[:, 1:])
        count = np.cumsum(flips, axis=1)
        ok = valid & (count[:, -1] >= 2) & np.all(np.isfinite(d), axis=1)
        result = np.empty((lengths.shape[0], 2))
        rows = np.arange(lengths.shape[0])
        for j in range(2):
            i = np.argmax(count >= j + 1, axis=1)
            d0, d1 = d[rows, i], d[rows, i + 1]
            result[:, j] = FREQ_GRID[i] + FREQ_STEP * d0 / (d0 - d1)
    ok &= np.all(np.isfinite(result), axis=1)
    result[~ok] = FALLBACK_HZ
    return result, ok


def area_function(tract_state: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """VTL area function of one tract state (19,): lengths (40,) cm, areas (40,) cm^2.

    Raises vocaltractlab_cython.VtlApiError or ValueError when VTL cannot compute it.
    """
    tube = vtl.tract_state_to_tube_state(
        np.asarray(tract_state, dtype=float),
        fast_calculation=True,
        save_tube_articulator=False,
        save_incisor_position=False,
        save_tongue_tip_side_elevation=False,
        save_velum_opening=False,
    )
    return np.asarray(tube["tube_length"], float), np.asarray(tube["tube_area"], float)


def tract_formants(tract_states: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Exact formants of VTL tract states (..., 19) -> log2 Hz (..., 2) and ok (...,) bool.

    About 3-5 ms per frame, nearly all of it in VTL's area function. Frames where VTL fails or
    no two resonances are found hold log2(FALLBACK_HZ) with ok False.
    """
    states = np.asarray(tract_states, dtype=float)
    batch = states.shape[:-1]
    flat = states.reshape(-1, states.shape[-1])
    lengths = np.full((flat.shape[0], N_SECTIONS), np.nan)
    areas = np.full((flat.shape[0], N_SECTIONS), np.nan)
    for n, state in enumerate(flat):
        try:
            lengths[n], areas[n] = area_function(state)
        except (vtl.VtlApiError, ValueError):
            pass  # left NaN: tube_formants flags the frame and gives it the fallback
    hz, ok = tube_formants(lengths, areas)
    return np.log2(hz).reshape(*batch, 2), ok.reshape(batch)
