"""The voice's audio, whichever tract sounds it: a movement's timing and the one WAV writer.

A 50-step movement sounds for `DEFAULT_DURATION_S` (0.5 s, i.e. 10 ms per control step, a
syllable-like rate of 6 vowels/s for a 3-vowel word), held for `DEFAULT_PAD_S` before and after
(VocalTractLab ramps its lung pressure there, sim/vocal/vtl/audio.py; DIVA's formant synthesizer
keeps the same timing, sim/vocal/diva/sound.py). `write_wav` writes every sound of the project:
a word (`playroom say`), a video's sound track.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from scipy.io import wavfile

DEFAULT_DURATION_S = 0.5  # s per 50-step movement
DEFAULT_PAD_S = 0.06  # s of held articulation before and after, for the pressure ramps
# Peak of a lone sound written as WAV (fraction of full scale): loud, with room to spare.
WAV_PEAK = 0.9


def write_wav(
    path: str | Path, waveform: np.ndarray, rate: int, peak: float | None = WAV_PEAK
) -> None:
    """Write a mono float waveform as 16-bit PCM WAV: the one WAV writer of the project.

    peak: the waveform is scaled to this peak (VTL's output level depends on the articulation,
    so a lone word is normalised to be heard; silence stays silence). None keeps the levels,
    as a mixed sound track needs, and clips to [-1, 1] so that the int16 conversion cannot wrap
    a loud sample around to the opposite sign.
    """
    wave = np.asarray(waveform).ravel()
    # A float32 track (the video's) stays float32: scaled in float64 instead, a sample at a
    # rounding boundary could land one step away. Anything else becomes float64.
    if wave.dtype not in (np.float32, np.float64):
        wave = wave.astype(np.float64)
    if not np.all(np.isfinite(wave)):
        raise ValueError("waveform contains NaN or infinite values")
    if peak is not None:
        if not 0 < peak <= 1:
            raise ValueError(f"peak must be in (0, 1], got {peak}")
        loudest = float(np.max(np.abs(wave))) if wave.size else 0.0
        if loudest > 0:
            wave = wave * (peak / loudest)
    pcm = np.round(np.clip(wave, -1.0, 1.0) * 32767).astype(np.int16)
    wavfile.write(str(path), int(rate), pcm)
