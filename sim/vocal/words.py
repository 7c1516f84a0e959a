"""The caregiver's words in any tract's formant space: their perfect trajectories and features.

Shared by every vocal tract (`sim.vocal.voice.Voice`): a tract gives its vowel targets (log2 Hz),
and the words follow from them here. A word of 3 vowels is a 5-point formant trajectory: v1,
mid(v1, v2), v2, mid(v2, v3), v3, in log2 Hz, midpoints taken in log2. Its 10D sound features are
the 5 log2 F1 values minus f1_offset, then the 5 log2 F2 values minus f2_offset (docs/protocol.md
§4, §6). VocalTractLab's own vowel targets and its words are in `sim.vocal.vtl.words`.
"""

from __future__ import annotations

import numpy as np

from sim.vocal.config import DEFAULT_VOICE, VoiceConfig


def normalise(log2_points: np.ndarray, config: VoiceConfig = DEFAULT_VOICE) -> np.ndarray:
    """(..., 5, 2) log2 Hz at the 5 points -> (..., 10) features: F1 block, then F2 block."""
    pts = np.asarray(log2_points, dtype=float)
    f1 = pts[..., 0] - config.f1_offset
    f2 = pts[..., 1] - config.f2_offset
    return np.concatenate([f1, f2], axis=-1)


def word_trajectory(
    word: str, targets: dict[str, np.ndarray], config: VoiceConfig = DEFAULT_VOICE
) -> np.ndarray:
    """(5, 2) log2 Hz: the perfect trajectory of a word (v1, mid, v2, mid, v3) between a
    tract's vowel targets (vowel name -> (2,) log2 Hz)."""
    if word not in config.words:
        raise ValueError(f"unknown word {word!r}; expected one of {config.words}")
    v1, v2, v3 = (np.asarray(targets[c], float) for c in word)
    return np.stack([v1, (v1 + v2) / 2, v2, (v2 + v3) / 2, v3])
