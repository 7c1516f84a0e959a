"""VocalTractLab's waveforms: articulator trajectories synthesised with VTL (the "vtl" voice).

The 50-step articulator trajectory becomes a sequence of VTL tract states at VTL's own frame
rate (110 samples = 2.5 ms at 44.1 kHz), linearly interpolated in articulator space. The movement
lasts `duration_s` (default 0.5 s for the 50 steps, i.e. 10 ms per control step, a syllable-like
rate of 6 vowels/s for a 3-vowel word). Before and after it the first and last articulation are
held for `pad_s` while the lung pressure ramps up and down, so the sound starts and ends without
clicks. The glottis is VTL's "modal" shape (F0 120 Hz, lung pressure 8000 dPa), the JD3
speaker's normal voice.
"""

from __future__ import annotations

import numpy as np
import vocaltractlab_cython as vtl

from sim.vocal.audio import DEFAULT_DURATION_S, DEFAULT_PAD_S
from sim.vocal.vtl.articulators import ArticulatorModel, default_articulators

GLOTTIS_SHAPE = "modal"
_PRESSURE_INDEX = 1  # "PR", lung pressure in dPa, in VTL's glottis parameter order
_F0_INDEX = 0  # "F0", Hz


def synthesise(
    artic_traj: np.ndarray,
    duration_s: float = DEFAULT_DURATION_S,
    pad_s: float = DEFAULT_PAD_S,
    f0_hz: float | None = None,
    articulators: ArticulatorModel | None = None,
) -> tuple[np.ndarray, int]:
    """Articulator trajectory (7, n_steps) in [-1, 1] -> (waveform (n_samples,) float in about
    [-1, 1], sample rate in Hz). f0_hz overrides the glottis shape's F0."""
    artic_traj = np.asarray(artic_traj, dtype=float)
    if artic_traj.ndim != 2 or artic_traj.shape[0] != 7:
        raise ValueError(f"articulator trajectory must be (7, n_steps); got {artic_traj.shape}")
    if not np.all(np.isfinite(artic_traj)) or np.any(np.abs(artic_traj) > 1.0):
        raise ValueError("articulator trajectory must be finite and in [-1, 1]")
    if duration_s <= 0 or pad_s < 0:
        raise ValueError("duration_s must be > 0 and pad_s >= 0")
    art = default_articulators() if articulators is None else articulators
    const = vtl.get_constants()
    rate, frame = int(const["sr_audio"]), int(const["n_samples_per_state"])
    frame_s = frame / rate

    n_move = max(2, round(duration_s / frame_s))
    n_pad = round(pad_s / frame_s)
    t_steps = np.linspace(0.0, 1.0, artic_traj.shape[1])
    t_frames = np.linspace(0.0, 1.0, n_move)
    moving = np.stack([np.interp(t_frames, t_steps, row) for row in artic_traj], axis=1)
    frames = np.vstack([np.repeat(moving[:1], n_pad, 0), moving, np.repeat(moving[-1:], n_pad, 0)])
    tract = art.to_tract(frames)  # (n_frames, 19)

    glottis = np.tile(vtl.get_shape(GLOTTIS_SHAPE, "glottis"), (len(frames), 1))
    if f0_hz is not None:
        glottis[:, _F0_INDEX] = f0_hz
    # Lung pressure ramps 0 -> full over the lead-in and back to 0 over the tail.
    envelope = np.ones(len(frames))
    if n_pad > 0:
        ramp = np.linspace(0.0, 1.0, n_pad)
        envelope[:n_pad] = ramp
        envelope[-n_pad:] = ramp[::-1]
    glottis[:, _PRESSURE_INDEX] *= envelope
    wave = np.asarray(vtl.synth_block(tract, glottis, state_samples=frame), dtype=float)
    return wave, rate
