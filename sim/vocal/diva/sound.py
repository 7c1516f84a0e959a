"""Audio for DIVA voices: a formant synthesizer at DIVA's formants, not DIVA's own sound.

DIVA's own sound synthesis needs its vocal tract outlines and area functions (the `vt` part of
its data) and code of its 2017 release that is not public unmodified, so videos of DIVA trials
sound through a cascade formant synthesizer instead, and say so on screen (`SOUND_LABEL`).

Klatt's (1980) cascade: a glottal pulse train at F0, smoothed by a low-pass resonator (Klatt's
"RGP", 0 Hz, 100 Hz bandwidth), through three formant resonators in series, then a first
difference for the lips' radiation. Formants change once per control step (10 ms, as the VTL
audio's 0.5 s per 50 steps) with each resonator's state carried across, so that no step
clicks. F0 is what DIVA's auditory output says for the study's fixed F0 articulator
(100 + 50 tanh(2) Hz, sim/vocal/diva/tract.py).
"""

from __future__ import annotations

import numpy as np
from scipy.signal import lfilter

from sim.vocal.audio import DEFAULT_DURATION_S, DEFAULT_PAD_S

SAMPLE_RATE = 22050  # Hz
BANDWIDTHS_HZ = (90.0, 110.0, 170.0)  # F1-F3 bandwidths, Klatt's defaults for a vowel
GLOTTAL_LOWPASS_HZ = 100.0  # bandwidth of Klatt's glottal low-pass resonator (at 0 Hz)
# Formants the resonators can hold: DIVA's map can give F1 <= 0 Hz (the study's "failed"
# frames), which no resonator sounds; such frames are clamped to the lowest.
LOWEST_HZ, HIGHEST_FRACTION = 50.0, 0.45  # Hz; fraction of the sample rate
SOUND_LABEL = "sound: formant synthesizer at DIVA's formants (not DIVA's own sound)"


def resonator(frequency_hz: float, bandwidth_hz: float, rate: int) -> tuple[list, list]:
    """(b, a) of Klatt's second-order digital resonator, unit gain at 0 Hz."""
    t = 1.0 / rate
    c = -np.exp(-2.0 * np.pi * bandwidth_hz * t)
    b = 2.0 * np.exp(-np.pi * bandwidth_hz * t) * np.cos(2.0 * np.pi * frequency_hz * t)
    return [1.0 - b - c], [1.0, -b, -c]


def glottal_pulses(f0_hz: float, n_samples: int, rate: int) -> np.ndarray:
    """A unit impulse at the start of every glottal period, smoothed by Klatt's low-pass."""
    phase = np.arange(n_samples) * f0_hz / rate
    pulses = np.diff(np.floor(phase), prepend=-1.0).clip(0.0, 1.0)
    b, a = resonator(0.0, GLOTTAL_LOWPASS_HZ, rate)
    return lfilter(b, a, pulses)


def synthesise_formants(
    formants_hz: np.ndarray,
    f0_hz: float,
    duration_s: float = DEFAULT_DURATION_S,
    pad_s: float = DEFAULT_PAD_S,
    rate: int = SAMPLE_RATE,
) -> tuple[np.ndarray, int]:
    """(n_steps, 3) F1-F3 in Hz, one row per control step -> (waveform peaking at 1, rate).

    The steps share `duration_s`; the first and last are held `pad_s` before and after, with
    the voice fading in and out over them, as VocalTractLab's audio does (sim/vocal/vtl/audio.py).
    """
    formants_hz = np.asarray(formants_hz, dtype=float)
    if formants_hz.ndim != 2 or formants_hz.shape[1] != 3 or len(formants_hz) == 0:
        raise ValueError(f"formants must have shape (n_steps, 3); got {formants_hz.shape}")
    if not np.all(np.isfinite(formants_hz)):
        raise ValueError("formants contain NaN or infinite values")
    step = max(1, round(duration_s / len(formants_hz) * rate))
    n_pad = round(pad_s * rate)
    per_sample = np.repeat(formants_hz, step, axis=0)
    per_sample = np.vstack(
        [np.repeat(per_sample[:1], n_pad, 0), per_sample, np.repeat(per_sample[-1:], n_pad, 0)]
    )
    per_sample = per_sample.clip(LOWEST_HZ, HIGHEST_FRACTION * rate)
    wave = glottal_pulses(f0_hz, len(per_sample), rate)
    # Formants held for `step` samples each (pads included): one filter call per block and
    # formant, its state carried to the next block.
    for f, bandwidth in enumerate(BANDWIDTHS_HZ):
        out = np.empty_like(wave)
        state = np.zeros(2)
        for start in range(0, len(wave), step):
            block = slice(start, start + step)
            b, a = resonator(per_sample[start, f], bandwidth, rate)
            out[block], state = lfilter(b, a, wave[block], zi=state)
        wave = out
    wave = np.diff(wave, prepend=0.0)  # radiation at the lips
    envelope = np.ones(len(wave))
    if n_pad > 0:
        envelope[:n_pad] = np.linspace(0.0, 1.0, n_pad)
        envelope[-n_pad:] = np.linspace(1.0, 0.0, n_pad)
    wave *= envelope
    loudest = float(np.max(np.abs(wave)))
    return (wave / loudest if loudest > 0 else wave), rate
