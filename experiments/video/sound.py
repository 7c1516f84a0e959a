"""The sound track of a video: clips placed at their time, resampled, levelled and mixed.

A clip is one sound of an iteration (the agent's voice, the caregiver's word) with the time it
starts in the video. `mix_audio` adds them into one mono track; `write_track` writes that track
as WAV through `sim.vocal.audio.write_wav`, the project's one WAV writer, with the levels kept.
"""

from __future__ import annotations

import math
import os
from collections.abc import Sequence
from pathlib import Path

import numpy as np
from scipy.signal import resample_poly

from sim.vocal.audio import write_wav

AUDIO_RATE = 44_100  # Hz of the mixed sound track
# Every clip is scaled to this peak: VocalTractLab's output level varies with the articulation
# (a word peaks near 0.06, a random babble near 0.002), and a video should let both be heard.
CLIP_PEAK = 0.5
MAX_CLIP_GAIN = 1000.0

# A clip of sound: (time in s, waveform (n,) float in [-1, 1], sample rate in Hz).
Clip = tuple[float, np.ndarray, int]


def mix_audio(
    clips: Sequence[Clip],
    duration_s: float,
    rate: int = AUDIO_RATE,
    peak: float | None = CLIP_PEAK,
) -> np.ndarray:
    """One mono track (n,) float32 in [-1, 1] of `duration_s`, n = round(duration_s * rate).

    clips: (time_s, waveform (m,) float in [-1, 1], rate_hz); each is resampled to `rate`,
    added at its time and cut at the end of the track. peak: each clip is scaled to this peak
    (gain at most `MAX_CLIP_GAIN`), so that a quiet babble is heard as well as a word; None
    keeps the clips' levels. Overlapping clips add up; the sum is clipped to [-1, 1] rather
    than wrapped around by the int16 conversion.
    """
    track = np.zeros(int(round(duration_s * rate)), dtype=np.float64)
    for k, (time_s, waveform, clip_rate) in enumerate(clips):
        wave = np.asarray(waveform, dtype=np.float64)
        if wave.ndim != 1:
            raise ValueError(f"audio clip {k}: waveform must be 1-D, got shape {wave.shape}")
        if not np.isfinite(wave).all():
            raise ValueError(f"audio clip {k}: waveform contains NaN or inf")
        if int(clip_rate) != clip_rate or clip_rate <= 0:
            raise ValueError(f"audio clip {k}: rate must be a positive integer, got {clip_rate}")
        if not math.isfinite(time_s) or time_s < 0:
            raise ValueError(f"audio clip {k}: time must be >= 0 s, got {time_s}")
        if clip_rate != rate:
            g = math.gcd(int(clip_rate), rate)
            wave = resample_poly(wave, rate // g, int(clip_rate) // g)
        if peak is not None and wave.size:
            # Silence (peak 0) stays silence; near-silence is not blown up into noise.
            loudest = np.abs(wave).max()
            wave = wave * min(peak / loudest, MAX_CLIP_GAIN) if loudest > 0 else wave
        start = int(round(time_s * rate))
        end = min(len(track), start + len(wave))
        if end > start:
            track[start:end] += wave[: end - start]
    return np.clip(track, -1.0, 1.0).astype(np.float32)


def write_track(
    path: str | os.PathLike,
    clips: Sequence[Clip],
    duration_s: float,
    rate: int = AUDIO_RATE,
) -> Path:
    """Mix `clips` into a track of `duration_s` (see `mix_audio`) and write it as 16-bit WAV
    at `rate` Hz; returns the path. The clips were levelled one by one when mixed, so the
    track is written as it is: normalising it as a whole would change their balance."""
    track = mix_audio(clips, duration_s, rate)
    out = Path(path)
    write_wav(out, track, rate, peak=None)
    return out
